"""Accuracy and registration time against registration.correspondence_reuse_m (docs/performance.md,
"Registration (GICP)": correspondences kept over Gauss-Newton iterations).

LiDAR-only scan pipeline (ScanPipeline) over the same scans for each reuse distance: generated
profiles (80 scans, with ground truth: APE and KITTI-style RPE) and recordings (no ground truth:
the largest position difference from the run without reuse). Medians over --rounds runs.

    python figures/performance_correspondence_reuse.py --profile urban --profile handheld --profile racetrack \
        --data ../shared/data/real/kitti_16_scans
"""

from __future__ import annotations

import argparse
import sys
import time

import farlio
import numpy as np
from farlio import _core
from farlio.benchmark import generated_scans
from harness import pipeline_config, recording_scans

REUSE_M = (0.0, 0.005, 0.01, 0.02, 0.05)
GENERATED_SCANS = 80
#: frames left out of the timing: the first has no map, the second no velocity yet
WARMUP_FRAMES = 2
MS_PER_S = 1e3


def run(scans: list, reuse_m: float, threads: int, rounds: int) -> tuple[float, float, object]:
    """(median frame ms, median registration ms, trajectory of the last round)."""
    frame, registration = [], []
    for _ in range(rounds):
        pipe = _core.ScanPipeline(pipeline_config(threads, {"registration.correspondence_reuse_m": str(reuse_m)}))
        traj = farlio.Trajectory()
        for k, s in enumerate(scans):
            t0 = time.perf_counter()
            r = pipe.process(s)
            ms = (time.perf_counter() - t0) * MS_PER_S
            traj.push_back(r.stamp_ns, r.pose)
            if k >= WARMUP_FRAMES:
                frame.append(ms)
                registration.append(r.timings.registration_s * MS_PER_S)
    return float(np.median(frame)), float(np.median(registration)), traj


def max_position_difference_m(a: object, b: object) -> float:
    return max(
        float(np.abs(np.asarray(a[i][1].translation) - np.asarray(b[i][1].translation)).max()) for i in range(len(a))
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", action="append", default=[], help="generated scans of this profile")
    ap.add_argument("--data", action="append", default=[], help="a recording (any format farlio run reads)")
    ap.add_argument("--threads", type=int, default=2, help="pipeline threads")
    ap.add_argument("--rounds", type=int, default=3, help="runs per reuse distance")
    args = ap.parse_args()
    sets = [(p, *generated_scans(p, GENERATED_SCANS)[:2]) for p in args.profile]
    sets += [(path, recording_scans(path), None) for path in args.data]
    columns = f"{'reuse m':>7s} {'frame ms':>9s} {'reg ms':>7s} {'APE m':>8s} {'RPE %':>7s} {'max |dpos| mm':>14s}"
    print(f"{'data':28s} {columns}")
    for name, scans, gt in sets:
        base = None
        for reuse in REUSE_M:
            frame_ms, reg_ms, traj = run(scans, reuse, args.threads, args.rounds)
            ape = rpe = float("nan")
            if gt is not None:
                e = _core.eval.evaluate(traj, gt)
                ape, rpe = e.ape.translation_m.rmse, e.kitti_rpe.translation_pct
            base = base or traj
            diff = max_position_difference_m(traj, base) * MS_PER_S
            print(f"{name[-28:]:28s} {reuse:7.3f} {frame_ms:9.2f} {reg_ms:7.2f} {ape:8.4f} {rpe:7.4f} {diff:14.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
