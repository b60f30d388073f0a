#!/usr/bin/env python3
"""Whether two builds give the same poses: each build (a directory holding a `farlio` package, put
first on PYTHONPATH in a process of its own) runs the LiDAR-only scan pipeline over the real KITTI
scans and generated urban scans; the largest difference between their pose matrices is printed
(0 when a change kept every float).

    python scripts/compare_poses.py --build before=DIR --build after=.venv/lib/python3.11/site-packages
        [--data ../shared/data/real/kitti_16_scans] [--urban-scans 40] [--threads 2]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

# Run inside each build's process: the poses of every frame, saved as one (frames, 4, 4) array.
_RUN = """
import sys
import numpy as np
from farlio import _core
from farlio.benchmark import generated_scans
from farlio.datasets import open_dataset

out_path, data, urban_scans, threads = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
sequences = []
if data:
    ds = open_dataset(data)
    sequences.append([ds.scan(i) for i in range(len(ds))])
if urban_scans > 0:
    sequences.append(generated_scans("urban", urban_scans)[0])
poses = []
for scans in sequences:
    config = _core.Config()
    config.set("num_threads", threads)
    config.set("device", "cpu")
    pipe = _core.ScanPipeline(config)
    poses += [np.array(pipe.process(s).pose.matrix()) for s in scans]
np.save(out_path, np.array(poses))
"""


def poses_of(build_dir: str, data: str, urban_scans: int, threads: int, out: Path) -> np.ndarray:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([build_dir, os.environ.get("PYTHONPATH", "")]))
    subprocess.run([sys.executable, "-c", _RUN, str(out), data, str(urban_scans), str(threads)], env=env, check=True)
    return np.load(out)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", action="append", required=True, help="NAME=DIR, twice (DIR holds a farlio package)")
    p.add_argument("--data", default="../shared/data/real/kitti_16_scans", help="a recording ('' for none)")
    p.add_argument("--urban-scans", type=int, default=40, help="generated urban scans (0 for none)")
    p.add_argument("--threads", type=int, default=2, help="threads of the pipeline")
    args = p.parse_args()
    if len(args.build) != 2:
        p.error("--build twice: NAME=DIR of the two builds to compare")
    builds = [b.split("=", 1) for b in args.build]
    data = args.data if args.data and Path(args.data).exists() else ""
    with tempfile.TemporaryDirectory() as tmp:
        poses = [
            poses_of(d, data, args.urban_scans, args.threads, Path(tmp) / f"{i}.npy") for i, (_, d) in enumerate(builds)
        ]
    if poses[0].shape != poses[1].shape:
        sys.exit(f"different frame counts: {poses[0].shape[0]} and {poses[1].shape[0]}")
    diff = np.abs(poses[0] - poses[1]).max(axis=(1, 2))
    (a, _), (b, _) = builds
    print(
        f"{a} vs {b}: {len(diff)} poses, {(diff == 0).sum()} bit-identical, "
        f"largest difference {diff.max():.3g} (frame {int(diff.argmax())})"
    )


if __name__ == "__main__":
    main()
