#!/usr/bin/env python3
"""Per-frame cost of the Python path (dataloader + bindings) next to the C++ pipeline alone
(docs/datasets.md, "Cost of the Python path").

Generates a short urban sequence, writes it as a sequence folder and as a ROS 2 MCAP bag, then
for every scan measures separately:
  * loading: `dataset.scan(i)` (folder: the C++ PCD reader through the bindings; bag: rosbags +
    the numpy PointCloud2 decoder + one copy into a farlio.Scan);
  * the call: wall time of `Odometry.process(scan)` seen from Python;
  * the pipeline: the C++ pipeline's own total time for that frame (timings.total_s).
The binding overhead is the call minus the pipeline. Prints medians in ms.

    .venv/bin/python figures/datasets_python_overhead.py [--seconds 5] [--threads 2]
"""

from __future__ import annotations

import argparse
import statistics
import time

from farlio import _core
from farlio.datasets import open_dataset
from farlio.datasets.rosbag_write import write_dataset
from farlio.runner import replay_options
from harness import generated_sequence, work_folder

MS_PER_S = 1e3
DEFAULT_SECONDS = 5.0


def measure(dataset, threads: int) -> dict[str, float]:
    config = _core.Config()
    if threads:
        config.set("num_threads", str(threads))
    odo = _core.Odometry(config, dataset.T_imu_lidar(), dataset.gravity_m_s2(), dataset.imu(), replay_options())
    load, call, pipeline = [], [], []
    for i in range(len(dataset)):
        t0 = time.perf_counter()
        scan = dataset.scan(i)
        t1 = time.perf_counter()
        fr = odo.process(scan)
        t2 = time.perf_counter()
        if not fr.processed:
            continue
        load.append((t1 - t0) * MS_PER_S)
        call.append((t2 - t1) * MS_PER_S)
        pipeline.append(fr.scan.timings.total_s * MS_PER_S)
    med = statistics.median
    return {
        "frames": len(load),
        "load_ms": med(load),
        "call_ms": med(call),
        "pipeline_ms": med(pipeline),
        "binding_ms": med(c - p for c, p in zip(call, pipeline)),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=DEFAULT_SECONDS, help="length of the generated sequence")
    parser.add_argument("--threads", type=int, default=0, help="pipeline threads (0: all)")
    args = parser.parse_args()
    with work_folder(prefix="farlio-overhead-") as tmp:
        seq = open_dataset(generated_sequence(tmp, "urban", duration_s=args.seconds))
        bag = write_dataset(seq, tmp / "bag", "mcap", "ouster")
        rows = {
            "sequence folder": measure(seq, args.threads),
            "ROS 2 MCAP bag": measure(open_dataset(bag), args.threads),
        }
    print(f"urban, {args.seconds:g} s, threads {args.threads or 'all'}; medians per frame in ms")
    print(f"{'input':18s} {'frames':>6s} {'load':>8s} {'binding':>8s} {'C++ pipeline':>13s} {'Python share':>13s}")
    for name, r in rows.items():
        share = (r["load_ms"] + r["binding_ms"]) / (r["load_ms"] + r["call_ms"])
        print(
            f"{name:18s} {r['frames']:6d} {r['load_ms']:8.2f} {r['binding_ms']:8.3f} {r['pipeline_ms']:13.2f} "
            f"{100 * share:12.1f}%"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
