#!/usr/bin/env python3
"""What refreshing map covariances costs and gains (map.refresh_covariances on/off, LiDAR-only,
generated urban 20 s and handheld 25 s, fixed 20 ms latency). Prints APE, RPE and the median
map-update and total time per frame. Used for docs/odometry.md."""
import csv, statistics, tempfile
from pathlib import Path
from farlio.simulation import generate
from farlio.datasets import open_dataset
from farlio.runner import run_dataset, replay_options
from farlio.config import load_config
d = Path(tempfile.mkdtemp())
for profile, dur in [("urban", 20.0), ("handheld", 25.0)]:
    generate(profile, d / profile, duration_s=dur)
    for refresh in ["true", "false"]:
        cfg = load_config(None, [f"map.refresh_covariances={refresh}", "fusion.enabled=false"])
        s = run_dataset(open_dataset(d / profile), d / f"{profile}_{refresh}", cfg, progress=False, plot=False, options=replay_options("fixed", 0.02))
        rows = list(csv.DictReader(open(d / f"{profile}_{refresh}" / "timing.csv")))
        mu = statistics.median(float(r["map_update_ms"]) for r in rows if r["map_update_ms"])
        tot = statistics.median(float(r["total_ms"]) for r in rows if r["total_ms"])
        a = s["accuracy"]
        print(profile, "refresh", refresh, "APE %.4f RPE %.3f %% map_update median %.2f ms total median %.2f ms" % (a["ape"]["translation_m"]["rmse"], a["kitti_rpe"]["translation_pct"], mu, tot))
