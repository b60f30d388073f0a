#!/usr/bin/env python3
"""What parts of a frame cost, by switching them off or on in turns (docs/performance.md, "Preprocessing" and
"Registration (GICP)": keys and deduplication in one loop, coarse to fine):
the LiDAR-only scan pipeline runs over the same scans once per variant and round, the variants
alternating so that all see the same machine load. Per data set and variant it prints the median
and p99 of the whole frame, the stage medians, and the registration time of the second frame
(which has no velocity yet: its guess is the identity, far from the pose).

Variants (config fields changed against the defaults):
  default           nothing
  no_coarse         registration.coarse_stride=1 (every Gauss-Newton iteration on all points)
  no_undistortion   preprocess.undistort=false
  no_shape_test     map.line_eigenvalue_ratio=1 (no eigenvalues: every covariance a surface)

    python figures/performance_frame_parts.py --data ../shared/data/real/kitti_16_scans --profile urban \\
        --threads 1 2 --rounds 3
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
from farlio import _core
from farlio.benchmark import STAGES, generated_scans
from harness import pipeline_config, recording_scans

MS_PER_S = 1e3
P99 = 99
#: the frame registered from the identity guess (the first starts the map)
SECOND_FRAME = 1
VARIANTS = {
    "default": {},
    "no_coarse": {"registration.coarse_stride": "1"},
    "no_undistortion": {"preprocess.undistort": "false"},
    "no_shape_test": {"map.line_eigenvalue_ratio": "1"},
}


def run(scans: list, threads: int, overrides: dict[str, str]) -> dict[str, list[float]]:
    """Per frame: the whole frame and each stage (ms), one pipeline over the scans."""
    pipe = _core.ScanPipeline(pipeline_config(threads, overrides))
    out: dict[str, list[float]] = {"total": [], **{s: [] for s in STAGES}}
    for scan in scans:
        t = pipe.process(scan).timings
        out["total"].append(t.total_s * MS_PER_S)
        for stage, attribute in STAGES.items():
            out[stage].append(getattr(t, attribute) * MS_PER_S)
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--data", action="append", default=[], help="a recording (repeatable)")
    p.add_argument("--profile", action="append", default=[], help="generated scans of this profile (repeatable)")
    p.add_argument("--scans", type=int, default=60, help="generated scans per profile")
    p.add_argument("--threads", type=int, nargs="+", default=[2])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    args = p.parse_args()
    sets = [(f"profile:{name}", generated_scans(name, args.scans)[0]) for name in args.profile]
    sets += [(path, recording_scans(path)) for path in args.data]
    for name, scans in sets:
        for threads in args.threads:
            runs: dict[str, list[dict[str, list[float]]]] = {v: [] for v in args.variants}
            for _ in range(args.rounds):
                for v in args.variants:
                    runs[v].append(run(scans, threads, VARIANTS[v]))
            print(f"\n{name}, {threads} thread(s), {args.rounds} rounds; ms")
            print(f"{'variant':16s} {'median':>7s} {'p99':>7s} " + " ".join(f"{s:>12s}" for s in STAGES) + "  2nd reg")
            for v, rs in runs.items():
                total = np.concatenate([r["total"] for r in rs])
                stages = " ".join(f"{np.median(np.concatenate([r[s] for r in rs])):12.2f}" for s in STAGES)
                second = np.median([r["registration"][SECOND_FRAME] for r in rs])
                print(f"{v:16s} {np.median(total):7.2f} {np.percentile(total, P99):7.2f} {stages} {second:8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
