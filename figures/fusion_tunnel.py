#!/usr/bin/env python3
"""The tunnel profile (docs/fusion.md, "Degeneracy", and its Figures table's tunnel row;
docs/simulation.md, "The tunnel"): LIO vs LiDAR-only where the scan does not constrain the motion
along the track. For each seed: generates the sequence (`farlio simulate tunnel`), runs
`farlio run --latency fixed --fixed-latency 0.02`, with the IMU and with --set fusion.enabled=false,
and prints, per mode, on the registered scan poses (scans_body.tum):

  APE         aligned translation RMSE over the whole run (m)
  rot raw     rotation RMSE without alignment (deg): both start level facing +x, and the SE(3)
              alignment of a straight path is rank deficient (any roll about the line fits equally,
              so the aligned rotation error can read ~180 deg)
  RPE         KITTI-style relative translation error over the whole run (%)
  RPE bare    the same, on the featureless section only (meta.yaml: featureless_start_s, _end_s)
  along end   along-track position error at the end of the featureless section, the estimate and the
              truth both taken relative to their first pose (m; + = ahead of the truth)
  slide       the part of it that grew inside the featureless section (m)

Usage: python figures/fusion_tunnel.py --seeds 1 2 [--duration 45] [--work DIR] [--set KEY=VALUE ...]
       [--modes lio lidar-only]   (a sequence already in --work is reused; without --work the
       sequences and runs go to a temporary folder, removed at the end)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import yaml
from farlio import _core
from farlio.cli import main as farlio
from farlio.evaluation import evaluate_files, make_options, result_to_dict
from harness import FIXED_LATENCY_S, MODES, ape_m, mode_overrides, rpe_pct, work_folder

ESTIMATE, GROUNDTRUTH = "scans_body.tum", "groundtruth.tum"


def along_track_error_m(est, gt, anchor_ns: int, at_ns: int) -> float:
    """(P_a^-1 P - Q_a^-1 Q) projected on the track direction (the true body x axis at at_ns)."""
    rel_est = est.interpolate_at(anchor_ns).inverse() * est.interpolate_at(at_ns)
    rel_gt = gt.interpolate_at(anchor_ns).inverse() * gt.interpolate_at(at_ns)
    track = np.asarray(rel_gt.rotation())[:, 0]
    return float(np.dot(np.asarray(rel_est.translation) - np.asarray(rel_gt.translation), track))


def measure(seq: Path, run_dir: Path, meta: dict) -> dict[str, float]:
    whole = evaluate_files(run_dir / ESTIMATE, seq / GROUNDTRUTH, plot=False)
    est = _core.io.read_trajectory(run_dir / ESTIMATE, "tum", None)
    gt = _core.io.read_trajectory(seq / GROUNDTRUTH, "tum", None)
    t0_ns = int(meta["start_stamp_ns"])
    bare0 = t0_ns + round(float(meta["featureless_start_s"]) * _core.NS_PER_S)
    bare1 = t0_ns + round(float(meta["featureless_end_s"]) * _core.NS_PER_S)
    bare = result_to_dict(_core.eval.evaluate(est.between(bare0, bare1), gt, make_options()))
    first = est[0][0]
    return {
        "APE": ape_m(whole),
        "rot raw": whole["ape"]["rotation_raw_deg"]["rmse"],
        "RPE": rpe_pct(whole),
        "RPE bare": rpe_pct(bare),
        "along end": along_track_error_m(est, gt, first, bare1),
        "slide": along_track_error_m(est, gt, bare0, bare1),
    }


def measure_seeds(args: argparse.Namespace, work: Path) -> tuple[list, dict]:
    """Per seed: the sequence generated into `work` (or the one there), each mode's run and figures."""
    rows = []
    for seed in args.seeds:
        seq = work / f"tunnel_s{seed}"
        sim = ["simulate", "tunnel", "--out", str(seq), "--seed", str(seed), "--no-progress"]
        if args.duration is not None:
            sim += ["--duration", str(args.duration)]
        if not (seq / "meta.yaml").exists() and farlio(sim) != 0:
            raise SystemExit(f"farlio simulate failed for seed {seed}")
        meta = yaml.safe_load((seq / "meta.yaml").read_text())
        for mode in args.modes:
            extra = [a for kv in mode_overrides(args.set, mode) for a in ("--set", kv)]
            out = work / f"run_s{seed}_{mode}"
            cmd = ["run", str(seq), "--out", str(out), "--latency", "fixed", "--fixed-latency", str(FIXED_LATENCY_S)]
            if farlio(cmd + extra + ["--no-progress", "--no-plot"]) != 0:
                raise SystemExit(f"farlio run failed for seed {seed} ({mode})")
            rows.append((seed, mode, measure(seq, out, meta)))
    return rows, meta


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--duration", type=float, default=None, help="seconds (default: the profile's, 45 s)")
    parser.add_argument(
        "--work",
        type=Path,
        default=None,
        help="folder for sequences and runs, kept (default: a temporary one, removed)",
    )
    parser.add_argument(
        "--set", action="append", default=[], metavar="KEY=VALUE", help="config override for both modes"
    )
    parser.add_argument("--modes", nargs="+", choices=list(MODES), default=list(MODES), help="modes to run")
    args = parser.parse_args()
    with work_folder(args.work, prefix="tunnel_") as work:
        rows, meta = measure_seeds(args, work)
    keys = list(rows[0][2])
    units = {"APE": "m", "rot raw": "deg", "RPE": "%", "RPE bare": "%", "along end": "m", "slide": "m"}
    where = args.work or "a temporary folder, removed"
    print(
        f"\ntunnel, featureless x in [{meta['featureless_start_x_m']}, {meta['featureless_end_x_m']}] m; work: {where}"
    )
    print(f"{'seed':>4} {'mode':>10} " + " ".join(f"{k + ' ' + units[k]:>13}" for k in keys))
    for seed, mode, m in rows:
        print(f"{seed:>4} {mode:>10} " + " ".join(f"{m[k]:>13.3f}" for k in keys))


if __name__ == "__main__":
    main()
