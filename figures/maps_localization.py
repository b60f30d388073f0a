#!/usr/bin/env python3
"""Odometry against localization in a saved map (docs/maps.md, "Figures"): map a generated sequence
once, then run a second pass over the same scene (other
noise seeds) twice, as odometry and localized in the saved map (`--prior-map`), with the same code
path as `farlio run` (run_dataset) on scans generated in memory (no sequence on disk: a racetrack
lap is ~7 GB of PCD). Prints per profile and pass seed:

  APE            aligned translation RMSE against the ground truth (m)
  err end        position error at the end of the pass, the estimate taken into the ground truth's
                 frame by its first pose (localization: by the mapping run's first pose, the map's
                 frame) (m); growth over the pass is drift
  vs map end/max the position error against the mapping run's pose at the same stamp, i.e. against
                 where the map says the scan is (only stamps the mapping run covers) (m)
  lost, min inl  localization: scans lost, smallest inlier fraction
  ms med/p99     per-frame processing time of the scan pipeline (same process, one after the other)

and the map's size, memory and export time per scan; writes error_over_time_<profile>.png (the
error in the ground truth's frame over time, odometry vs localization) and maps.json into --out.

With --global-map, a third mode per pass: localization in the global map of `farlio run
--loop-closure --save-map` over a mapping run as long as a pass (map_global.pcd: every keyframe's
segment at its loop-closed pose), against the single-pass map; its "vs map" columns compare with
the mapping run's global poses (scans_body_global.tum).

Usage: python figures/maps_localization.py [--profiles urban handheld racetrack] [--pass-seeds 2 3]
       [--global-map] [--out DIR]
Racetrack: the map is the first lap (85 s), each pass two laps (165 s); the global map two laps.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from farlio import _core
from farlio.loop_closure import SCANS_BODY_GLOBAL_TUM
from farlio.mapping import MAP_GLOBAL_PCD, MAP_PCD, MapOptions
from farlio.runner import SCANS_BODY_TUM
from harness import ape_m, config, floats, generated_dataset, run, timing_rows, work_folder

#: (map duration, pass duration) in seconds
DURATIONS_S = {"urban": (60.0, 60.0), "handheld": (60.0, 60.0), "racetrack": (85.0, 165.0), "tunnel": (45.0, 45.0)}
MAP_SEED = 1


def poses(path: Path) -> dict[int, np.ndarray]:
    t = _core.io.read_trajectory(path)
    return {t[i][0]: t[i][1].matrix() for i in range(len(t))}


def error_in_gt_frame(est: dict, gt: dict, frame_est: dict) -> tuple[np.ndarray, np.ndarray]:
    """(seconds from the start, position error) of est against gt, est taken into gt's frame by the
    first pose of frame_est (est itself, or the mapping run whose frame a localization shares)."""
    s0 = min(frame_est)
    T = gt[s0] @ np.linalg.inv(frame_est[s0])
    stamps = [s for s in sorted(est) if s in gt]
    err = np.array([np.linalg.norm((T @ est[s])[:3, 3] - gt[s][:3, 3]) for s in stamps])
    return (np.array(stamps) - stamps[0]) / 1e9, err


def frame_stats(out: Path) -> tuple[float, float, float]:
    """(median, p99 frame time in ms, smallest inlier fraction) of a run's timing.csv."""
    rows = timing_rows(out, "total_ms")
    ms, inliers = floats(rows, "total_ms"), floats(rows, "inlier_fraction")
    return float(np.median(ms)), float(np.percentile(ms, 99)), min(inliers, default=float("nan"))


def measure(profile: str, pass_seeds: list[int], out: Path, work: Path, global_map: bool = False) -> dict:
    map_s, pass_s = DURATIONS_S[profile]
    mapping = run(
        generated_dataset(profile, MAP_SEED, map_s, work), work / f"{profile}-map", config(), MapOptions(save=True)
    )
    mapping_poses = {"localization": poses(work / f"{profile}-map" / SCANS_BODY_TUM)}
    modes = [("odometry", MapOptions()), ("localization", MapOptions(prior_map=work / f"{profile}-map" / MAP_PCD))]
    result = {"map": mapping["map"], "mapping_ape_m": ape_m(mapping["accuracy"]), "passes": {}}
    if global_map:
        o = work / f"{profile}-map-global"
        closed = run(
            generated_dataset(profile, MAP_SEED, pass_s, work), o, config(), MapOptions(True, loop_closure=True)
        )
        mapping_poses["global map"] = poses(o / SCANS_BODY_GLOBAL_TUM)
        modes.append(("global map", MapOptions(prior_map=o / MAP_GLOBAL_PCD)))
        result["global_mapping_ape_m"] = ape_m(closed["accuracy_global"])
    curves = {}
    for seed in pass_seeds:
        row = {}
        for mode, maps in modes:
            data = generated_dataset(profile, seed, pass_s, work)
            o = work / f"{profile}-{seed}-{mode.replace(' ', '-')}"
            s = run(data, o, config(), maps)
            est, gt = poses(o / SCANS_BODY_TUM), poses(data.gt_scans)
            frame = mapping_poses.get(mode, est)
            t, err = error_in_gt_frame(est, gt, frame)
            reference = mapping_poses.get(mode, mapping_poses["localization"])
            common = [k for k in sorted(est) if k in reference]
            vs_map = np.array([np.linalg.norm(est[k][:3, 3] - reference[k][:3, 3]) for k in common])
            t_map = (np.array(common) - common[0]) / 1e9
            med, p99, min_inliers = frame_stats(o)
            row[mode] = {
                "ape_m": ape_m(s["accuracy"]),
                "err_end_m": float(err[-1]),
                "vs_map_end_m": float(vs_map[-1]),
                "vs_map_max_m": float(vs_map.max()),
                "frame_ms_median": med,
                "frame_ms_p99": p99,
            }
            if mode != "odometry":
                loc = s["localization"]
                row[mode] |= {
                    "lost": loc["frames_lost"],
                    "localized": loc["frames_localized"],
                    "min_inlier_fraction": min_inliers,
                }
            curves.setdefault(seed, {})[mode] = {"gt": (t, err), "map": (t_map, vs_map)}
        result["passes"][seed] = row
    plot_curves(profile, curves, out / f"error_over_time_{profile}.png")
    return result


def plot_curves(profile: str, curves: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    for ax, key, title in (
        (axes[0], "map", "against the map (the mapping run's pose at the same stamp)"),
        (axes[1], "gt", "against the ground truth (aligned at the start)"),
    ):
        for i, (seed, modes) in enumerate(sorted(curves.items())):
            for mode, style in (("odometry", "--"), ("localization", "-"), ("global map", ":")):
                if mode not in modes:
                    continue
                t, err = modes[mode][key]
                ax.plot(t, err, style, color=f"C{i}", label=f"{mode}, seed {seed}")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("position error [m]")
        ax.set_title(title, fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"{profile}: odometry vs localization in the map of seed {MAP_SEED}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profiles", nargs="+", default=["urban", "handheld", "racetrack"], choices=list(DURATIONS_S))
    ap.add_argument("--pass-seeds", nargs="+", type=int, default=[2, 3])
    ap.add_argument("--global-map", action="store_true", help="also localize in the loop-closed map (module doc)")
    ap.add_argument("--out", type=Path, default=Path("maps_measure"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    results = {}
    with work_folder(prefix="farlio-maps-") as tmp:
        for profile in args.profiles:
            r = measure(profile, args.pass_seeds, args.out, tmp, args.global_map)
            results[profile] = r
            m = r["map"]
            print(
                f"\n{profile}: map {m['points']} points at {m['resolution_m']:.2f} m, "
                f"{m['memory_bytes'] / 2**20:.1f} MiB, export {m['add_ms_median']:.1f} ms/scan median; "
                f"mapping run APE {r['mapping_ape_m']:.3f} m"
                + (f", global {r['global_mapping_ape_m']:.3f} m" if "global_mapping_ape_m" in r else "")
            )
            print(f"{'seed':>4} {'mode':<13} {'APE m':>7} {'err end m':>9} {'vs map end':>10} {'vs map max':>10} "
                  f"{'lost':>5} {'min inl':>7} {'ms med':>7} {'ms p99':>7}")  # fmt: skip
            for seed, row in r["passes"].items():
                for mode, v in row.items():
                    inliers = v.get("min_inlier_fraction", float("nan"))
                    print(
                        f"{seed:>4} {mode:<13} {v['ape_m']:7.3f} {v['err_end_m']:9.3f} {v['vs_map_end_m']:10.3f} "
                        f"{v['vs_map_max_m']:10.3f} {v.get('lost', ''):>5} {inliers:7.3f} "
                        f"{v['frame_ms_median']:7.2f} {v['frame_ms_p99']:7.2f}"
                    )
            (args.out / "maps.json").write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
