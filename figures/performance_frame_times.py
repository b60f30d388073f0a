#!/usr/bin/env python3
"""The largest frames of one LiDAR-only run (docs/performance.md, "Whole frame next to KISS-ICP"),
from the stage times the pipeline measures itself (`FrameResult.timings`), without the rest of
`farlio bench` in the process (no KISS-ICP, no yardsticks): the median and p99 of the whole frame
and, per largest frame, its stages (docs/performance.md: the first frame builds the submap and is
the largest).

    python figures/performance_frame_times.py --profile urban --scans 100 --threads 2 [--data DIR] [--top 8] \
        [--repeat N]

With --repeat N the scans run N times, each time through a new pipeline (the frames of all runs
counted): enough frames of a short recording for `perf record` to sample (docs/performance.md).
"""

from __future__ import annotations

import argparse

import numpy as np
from farlio import _core
from farlio.benchmark import STAGES, generated_scans
from harness import pipeline_config, recording_scans

MS_PER_S = 1e3
P99 = 99


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--profile", default="urban", help="generated scans of this profile (without --data)")
    p.add_argument("--data", help="a recording instead (any format farlio run reads)")
    p.add_argument("--scans", type=int, default=100, help="generated scans")
    p.add_argument("--threads", type=int, default=2, help="threads of the pipeline")
    p.add_argument("--top", type=int, default=8, help="largest frames listed")
    p.add_argument("--repeat", type=int, default=1, help="runs over the scans, each with a new pipeline")
    args = p.parse_args()
    scans = recording_scans(args.data) if args.data else generated_scans(args.profile, args.scans)[0]
    config = pipeline_config(args.threads)
    rows = []
    for _ in range(max(1, args.repeat)):
        pipe = _core.ScanPipeline(config)
        for i, scan in enumerate(scans):
            t = pipe.process(scan).timings
            rows.append((t.total_s * MS_PER_S, i, [getattr(t, a) * MS_PER_S for a in STAGES.values()]))
    total = np.array([r[0] for r in rows])
    median, p99 = float(np.median(total)), float(np.percentile(total, P99))
    print(
        f"{len(rows)} frames, {args.threads} thread(s): median {median:.2f} ms, p99 {p99:.2f} ms, "
        f"p99 / median {p99 / median:.2f}"
    )
    for ms, i, stages in sorted(rows, reverse=True)[: args.top]:
        parts = " ".join(f"{name} {v:.2f}" for name, v in zip(STAGES, stages, strict=True))
        print(f"frame {i:4d}: {ms:.2f} ms ({ms / median:.2f}x the median) | {parts}")


if __name__ == "__main__":
    main()
