#!/usr/bin/env python3
"""What refreshing map covariances costs and gains (map.refresh_covariances on/off, LiDAR-only,
generated urban 20 s and handheld 25 s, fixed 20 ms latency). Prints APE, RPE and the median
map-update and total time per frame. Used for docs/odometry.md."""

import csv
import statistics
import tempfile
from pathlib import Path

from farlio.config import load_config
from farlio.datasets import open_dataset
from farlio.runner import replay_options, run_dataset
from farlio.simulation import generate

d = Path(tempfile.mkdtemp())
for profile, dur in [("urban", 20.0), ("handheld", 25.0)]:
    generate(profile, d / profile, duration_s=dur)
    for refresh in ["true", "false"]:
        cfg = load_config(None, [f"map.refresh_covariances={refresh}", "fusion.enabled=false"])
        s = run_dataset(
            open_dataset(d / profile),
            d / f"{profile}_{refresh}",
            cfg,
            progress=False,
            plot=False,
            options=replay_options("fixed", 0.02),
        )
        rows = list(csv.DictReader(open(d / f"{profile}_{refresh}" / "timing.csv")))
        mu = statistics.median(float(r["map_update_ms"]) for r in rows if r["map_update_ms"])
        tot = statistics.median(float(r["total_ms"]) for r in rows if r["total_ms"])
        a = s["accuracy"]
        print(
            profile,
            "refresh",
            refresh,
            f"APE {a['ape']['translation_m']['rmse']:.4f} RPE {a['kitti_rpe']['translation_pct']:.3f} % "
            f"map_update median {mu:.2f} ms total median {tot:.2f} ms",
        )
