#!/usr/bin/env python3
"""One parameter set for any LiDAR (docs/fusion.md, "Every profile with every LiDAR model"): the LIO
against LiDAR-only on each profile with each of the simulator's LiDAR models, the same defaults
everywhere.

For each profile, LiDAR model and seed the generator records `--duration` seconds from rest
(`farlio simulate PROFILE --lidar L`, in memory), and the deterministic replay (fixed 20 ms latency)
runs it with the IMU and with `fusion.enabled=false`. One markdown row per profile and LiDAR: the
scan poses' APE (m, aligned RMSE), KITTI-style RPE (%), rotation RMSE (deg) after the APE's
alignment and rotation RMSE aligned at the first pose (deg, `farlio eval --align-origin`) of
both modes, each
cell the seeds separated by " / ", a metric in bold where the LIO is worse than LiDAR-only on some
seed; then the LIO's registration failures, re-initialisations and rejected LiDAR groups, summed
over the seeds, and whether its filter started (a narrow field of view on the racetrack never
gives it the scans that constrain every direction it starts from: docs/fusion.md, "Degeneracy").

  python figures/fusion_sensor_matrix.py --profiles racetrack urban handheld --duration 20 --seeds 1 2
"""

from __future__ import annotations

import argparse

from farlio.simulation import LIDAR_MODELS, PROFILES, Recording, make_config, replay, stretch_accuracy
from harness import FIXED_LATENCY_S, LIDAR_ONLY

METRICS = ("ape_m", "rpe_pct", "rot_deg", "rot_origin_deg")


def cell(values: list[float]) -> str:
    return " / ".join(f"{v:.3f}" for v in values)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--profiles", nargs="+", choices=PROFILES, default=["racetrack", "urban", "handheld"])
    p.add_argument("--lidars", nargs="+", choices=LIDAR_MODELS, default=list(LIDAR_MODELS))
    p.add_argument("--duration", type=float, default=20.0)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    args = p.parse_args()
    head = ["profile, LiDAR"]
    for metric in METRICS:
        head += [f"LIO {metric}", f"LiDAR-only {metric}"]
    head += ["LIO failed / re-inits / rejected", "filter started"]
    seeds = " / ".join(map(str, args.seeds))
    print(f"{args.duration:g} s from rest, seeds {seeds}, fixed {FIXED_LATENCY_S * 1e3:g} ms latency")
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for profile in args.profiles:
        for lidar in args.lidars:
            lio, lo = [], []
            for seed in args.seeds:
                rec = Recording(make_config(profile, seed=seed, duration_s=args.duration, lidar=lidar))
                for rows, overrides in ((lio, []), (lo, [LIDAR_ONLY])):
                    run = replay(rec, overrides, fixed_latency_s=FIXED_LATENCY_S)
                    rows.append(stretch_accuracy(run))
            row = [f"{profile}, {lidar}"]
            for metric in METRICS:
                a, b = [r[metric] for r in lio], [r[metric] for r in lo]
                worse = any(x > y for x, y in zip(a, b))
                row += [f"**{cell(a)}**" if worse else cell(a), cell(b)]
            counts = [sum(int(r.get(k, 0) or 0) for r in lio) for k in ("failed", "reinit", "rejected")]
            started = ["yes" if "initialization" in r and r["initialization"].initialized else "no" for r in lio]
            row += [" / ".join(map(str, counts)), " / ".join(started)]
            print("| " + " | ".join(row) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
