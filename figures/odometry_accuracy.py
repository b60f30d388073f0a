#!/usr/bin/env python3
"""Accuracy of the LIO and of LiDAR-only odometry on generated urban (10 s) and handheld (25 s)
sequences (seed 1, fixed 20 ms latency): the measured values behind the bounds of
tests/python/test_odometry.py, of docs/odometry.md, "Measured figures" ("Accuracy against exact
ground truth") and of the urban and handheld rows of docs/fusion.md's Figures table.
`--set NAME=VALUE` (repeatable) overrides a config field in both modes.

    python figures/odometry_accuracy.py [--set fusion.standstill.max_speed_m_s=0.4 ...]
"""

from __future__ import annotations

import argparse

from harness import MODES, ape_m, config, generated_sequence, rpe_pct, run, work_folder


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE")
    args = p.parse_args()
    with work_folder(prefix="farlio-accuracy-") as work:
        for profile, duration in (("urban", 10.0), ("handheld", 25.0)):
            seq = generated_sequence(work, profile, duration_s=duration)
            for mode in MODES:
                s = run(seq, work / f"{profile}_{mode}", config(args.overrides, mode))
                a, o = s["accuracy"], s.get("accuracy_odometry")
                line = f"{profile} {duration:g} s {mode}: scan poses APE {ape_m(a):.4f} m, RPE {rpe_pct(a):.3f} %"
                if o:
                    line += f"; 100 Hz odometry APE {ape_m(o):.4f} m"
                print(line + f" (voxel {s['voxel_size_m']:.2f} m)")


if __name__ == "__main__":
    main()
