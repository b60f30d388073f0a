#!/usr/bin/env python3
"""The map's scale chosen at the first scan (docs/odometry.md, step 0 "Scale"): the range rule
alone (clamp(p90 range / 6, 1 m, 4 m), the earlier default) against the default, which also
shrinks the voxel until the first scan fills map.auto_min_voxels of them (down to
map.auto_min_voxel_size_m), on generated sequences of one profile with each LiDAR model.

For each LiDAR and seed: generates the sequence (`farlio simulate PROFILE --lidar L`), runs the
deterministic replay (`farlio run --latency fixed --fixed-latency 0.02`) with each rule, with the
IMU and LiDAR-only (--set fusion.enabled=false), and prints one markdown row per LiDAR and rule:
the voxel picked and, per mode, the scan poses' APE (m, aligned RMSE) and KITTI-style RPE (%),
then registration failures and re-initialisations (LIO) summed over the seeds; each figure cell
lists the seeds separated by " / ".

Usage: python figures/odometry_scene_scale.py --profile handheld --duration 30 --seeds 1 2 \
           [--lidars avia mid360 vlp16 hdl32 os128 profile] [--work DIR]

A cut of such a sequence (started while moving): figures/fusion_start_in_motion.py --lidar L.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from harness import ape_m, config, generated_sequence, rpe_pct, run, table_row, work_folder

#: the range rule alone: no voxel count, the earlier 1 m floor
RANGE_RULE = ["map.auto_min_voxels=0", "map.auto_min_voxel_size_m=1.0"]
RULES = {"range rule": RANGE_RULE, "default": []}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", default="handheld")
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--lidars", nargs="+", default=["avia", "mid360", "vlp16", "hdl32", "os128", "profile"])
    ap.add_argument("--work", type=Path, default=None)
    args = ap.parse_args()
    print(
        table_row(
            "LiDAR",
            "rule",
            "voxel m",
            "LIO APE m",
            "LIO RPE %",
            "LiDAR-only APE m",
            "LiDAR-only RPE %",
            "failures LIO / LO",
            "re-inits",
        )
    )
    with work_folder(args.work) as work:
        for lidar in args.lidars:
            seqs = [
                generated_sequence(work / lidar, args.profile, seed, args.duration, lidar=lidar) for seed in args.seeds
            ]
            for rule, overrides in RULES.items():
                cells: dict[str, list[str]] = {k: [] for k in ("voxel", "lio_ape", "lio_rpe", "lo_ape", "lo_rpe")}
                failures = {"lio": 0, "lidar-only": 0}
                reinits = 0
                for seq in seqs:
                    for mode in ("lio", "lidar-only"):
                        out = work / "runs" / f"{seq.name}_{lidar}_{rule.replace(' ', '_')}_{mode}"
                        s = run(seq, out, config(overrides, mode))
                        a = s["accuracy"]
                        key = "lio" if mode == "lio" else "lo"
                        cells[f"{key}_ape"].append(f"{ape_m(a):.3f}")
                        cells[f"{key}_rpe"].append(f"{rpe_pct(a):.2f}")
                        failures[mode] += int(s["registration_failed"])
                        if mode == "lio":
                            reinits += int(s.get("fusion", {}).get("reinitializations", 0))
                            cells["voxel"].append(f"{s['voxel_size_m']:.2f}")
                print(
                    table_row(
                        lidar,
                        rule,
                        " / ".join(cells["voxel"]),
                        " / ".join(cells["lio_ape"]),
                        " / ".join(cells["lio_rpe"]),
                        " / ".join(cells["lo_ape"]),
                        " / ".join(cells["lo_rpe"]),
                        f"{failures['lio']} / {failures['lidar-only']}",
                        reinits,
                    ),
                    flush=True,
                )


if __name__ == "__main__":
    main()
