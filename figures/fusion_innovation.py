#!/usr/bin/env python3
"""How well the filter's noise fits its sensors (docs/fusion.md, "Innovation statistics"): the
LiDAR updates' normalised innovations squared (NIS) per degree of freedom, and the share beyond the
chi-squared 95 % quantile, for each profile with each LiDAR model and IMU.

A filter whose noise fits its data has a mean NIS per degree of freedom of 1 and 5 % beyond the
quantile; below 1 it trusts its prediction and the LiDAR less than the data allow, above 1 more.
For each profile, LiDAR model, IMU (`profile` or `racing`, as figures/fusion_imu_rates.py) and seed
the generator records `--duration` seconds from rest (in memory) and the replay runs the LIO with
the defaults (fixed 20 ms latency). One row per profile, LiDAR and IMU: the pose group's and the
velocity group's mean NIS per degree of freedom and share beyond the quantile, the seeds separated by
" / ".

  python figures/fusion_innovation.py --profiles racetrack urban handheld --duration 20 --seeds 1 2
"""

from __future__ import annotations

import argparse

from farlio.simulation import LIDAR_MODELS, PROFILES, replay
from fusion_imu_rates import recording
from harness import FIXED_LATENCY_S


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--profiles", nargs="+", choices=PROFILES, default=["racetrack", "urban", "handheld"])
    p.add_argument("--lidars", nargs="+", choices=LIDAR_MODELS, default=list(LIDAR_MODELS))
    p.add_argument("--imus", nargs="+", choices=["profile", "racing"], default=["profile"])
    p.add_argument("--duration", type=float, default=20.0)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    args = p.parse_args()
    print(f"{args.duration:g} s from rest, seeds {' / '.join(map(str, args.seeds))}, fixed latency")
    print("| profile, LiDAR, IMU | pose NIS / dof | pose beyond 95 % | velocity NIS / dof | velocity beyond 95 % |")
    print("|---|---|---|---|---|")
    for profile in args.profiles:
        for lidar in args.lidars:
            for imu in args.imus:
                cells: dict[str, list[str]] = {}
                for seed in args.seeds:
                    rec = recording(profile, seed, args.duration, imu, lidar=lidar)
                    stats = replay(rec, [], fixed_latency_s=FIXED_LATENCY_S).stats
                    groups = {g.group: g for g in stats.lidar_innovation}
                    for name in ("pose", "velocity"):  # "–": the filter never started
                        g = groups.get(name)
                        cells.setdefault(f"{name} mean", []).append(f"{g.mean_per_dof:.3f}" if g else "–")
                        cells.setdefault(f"{name} share", []).append(f"{100 * g.share_beyond_95:.0f} %" if g else "–")
                row = [f"{profile}, {lidar}, {imu}"]
                for key in ("pose mean", "pose share", "velocity mean", "velocity share"):
                    row.append(" / ".join(cells[key]))
                print("| " + " | ".join(row) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
