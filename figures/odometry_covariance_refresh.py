#!/usr/bin/env python3
"""What refreshing map covariances costs and gains (docs/odometry.md, "Measured figures": "Refreshing
map covariances"): map.refresh_covariances on and off, LiDAR-only, generated urban 20 s and
handheld 25 s, fixed 20 ms latency. Prints APE, RPE and the median map-update and total time per
frame.

    python figures/odometry_covariance_refresh.py
"""

from __future__ import annotations

import argparse
import statistics

from harness import ape_m, config, floats, generated_sequence, rpe_pct, run, timing_rows, work_folder

SEQUENCES = (("urban", 20.0), ("handheld", 25.0))


def main() -> None:
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    with work_folder(prefix="farlio-refresh-") as work:
        for profile, duration in SEQUENCES:
            seq = generated_sequence(work, profile, duration_s=duration)
            for refresh in ["true", "false"]:
                out = work / f"{profile}_{refresh}"
                s = run(seq, out, config([f"map.refresh_covariances={refresh}"], "lidar-only"))
                rows = timing_rows(out)
                mu = statistics.median(floats(rows, "map_update_ms"))
                tot = statistics.median(floats(rows, "total_ms"))
                a = s["accuracy"]
                figures = f"APE {ape_m(a):.4f} RPE {rpe_pct(a):.3f} % "
                print(profile, "refresh", refresh, figures + f"map_update median {mu:.2f} ms total median {tot:.2f} ms")


if __name__ == "__main__":
    main()
