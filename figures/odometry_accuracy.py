#!/usr/bin/env python3
"""Accuracy of the LIO and of LiDAR-only odometry on generated urban (10 s) and handheld (25 s)
sequences (seed 1, fixed 20 ms latency): the measured values behind the bounds of
tests/python/test_odometry.py and the table in docs/odometry.md. `--set NAME=VALUE` (repeatable)
overrides a config field in both modes, e.g. `--set fusion.standstill_max_speed_m_s=0.4`."""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from farlio.config import load_config
from farlio.datasets import open_dataset
from farlio.runner import replay_options, run_dataset
from farlio.simulation import generate


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE")
    args = p.parse_args()
    root = Path(tempfile.mkdtemp())
    for profile, duration in (("urban", 10.0), ("handheld", 25.0)):
        generate(profile, root / profile, duration_s=duration)
        for mode in ("lio", "lidar-only"):
            cfg = load_config(None, [*args.overrides, *([] if mode == "lio" else ["fusion.enabled=false"])])
            s = run_dataset(
                open_dataset(root / profile),
                root / f"{profile}_{mode}",
                cfg,
                progress=False,
                plot=False,
                options=replay_options("fixed", 0.02),
            )
            a, o = s["accuracy"], s.get("accuracy_odometry")
            line = (
                f"{profile} {duration:g} s {mode}: scan poses APE {a['ape']['translation_m']['rmse']:.4f} m, "
                f"RPE {a['kitti_rpe']['translation_pct']:.3f} %"
            )
            if o:
                line += f"; 100 Hz odometry APE {o['ape']['translation_m']['rmse']:.4f} m"
            print(line + f" (voxel {s['voxel_size_m']:.2f} m)")


if __name__ == "__main__":
    main()
