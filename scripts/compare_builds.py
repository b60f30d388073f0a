"""Stage times of two builds of farlio on the same scans, in the same run (docs/performance.md).

Each build is a folder that holds an installed `farlio` package (e.g. a copy of
.venv/lib/python3.11/site-packages/farlio taken before a change). The builds run in turns, one
subprocess per build and round, so that both see the same machine load; per build the frame and
stage times of all rounds are pooled and summarised (median, p99).

    python scripts/compare_builds.py --build before=/tmp/before --build after=.venv/lib/python3.11/site-packages \
        --data ../shared/data/real/kitti_16_scans --profile urban --threads 1 2
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

import numpy as np

STAGES = ("total", "preprocess", "covariance", "registration", "map_update")
#: generated scans per profile (urban starts at rest: farlio.benchmark skips the first 2.5 s)
GENERATED_SCANS = 60
#: frames skipped per run: the first has no map, the second no velocity yet
WARMUP_FRAMES = 2

#: the worker reads FrameResult.timings directly instead of calling farlio.benchmark.run_farlio,
#: so that it runs on builds from before that function gave stage times
WORKER = r"""
import json, sys, time
from farlio import _core
from farlio.benchmark import generated_scans
from farlio.datasets import open_dataset
source, threads, scans_n = sys.argv[1], sys.argv[2], int(sys.argv[3])
if source.startswith("profile:"):
    scans, _, _ = generated_scans(source.split(":", 1)[1], scans_n)
else:
    ds = open_dataset(source)
    scans = [ds.scan(i) for i in range(len(ds))]
cfg = _core.Config()
cfg.set("num_threads", threads)
cfg.set("device", "cpu")
pipe = _core.ScanPipeline(cfg)
rows = []
for k, s in enumerate(scans):
    t0 = time.perf_counter()
    r = pipe.process(s)
    total = time.perf_counter() - t0
    t = r.timings
    if k >= int(sys.argv[4]):
        rows.append([total, t.preprocess_s, t.covariance_s, t.registration_s, t.map_update_s])
print(json.dumps(rows))
"""


def run_once(package_dir: str, source: str, threads: int) -> list[list[float]]:
    env = dict(os.environ, PYTHONPATH=package_dir)
    out = subprocess.run(
        [sys.executable, "-c", WORKER, source, str(threads), str(GENERATED_SCANS), str(WARMUP_FRAMES)],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", action="append", required=True, help="NAME=DIR holding the farlio package")
    ap.add_argument("--data", action="append", default=[], help="a recording (any format farlio run reads)")
    ap.add_argument("--profile", action="append", default=[], help="generated scans of this profile")
    ap.add_argument("--threads", type=int, nargs="+", default=[2], help="thread counts")
    ap.add_argument("--rounds", type=int, default=5, help="runs per build, taken in turns")
    args = ap.parse_args()
    builds = dict(b.split("=", 1) for b in args.build)
    sources = args.data + [f"profile:{p}" for p in args.profile]
    for source in sources:
        for threads in args.threads:
            pooled: dict[str, list[list[float]]] = {name: [] for name in builds}
            for _ in range(args.rounds):
                for name, folder in builds.items():
                    pooled[name] += run_once(folder, source, threads)
            print(f"\n{source}, {threads} thread(s), {args.rounds} rounds; ms median / p99")
            print(f"{'build':10s}" + "".join(f"{s:>22s}" for s in STAGES))
            for name, rows in pooled.items():
                a = np.asarray(rows) * 1e3
                cells = "".join(f"{np.median(a[:, i]):12.2f} / {np.percentile(a[:, i], 99):6.2f}" for i in range(5))
                print(f"{name:10s}{cells}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
