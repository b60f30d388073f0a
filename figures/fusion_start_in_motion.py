#!/usr/bin/env python3
"""Starting in motion (docs/fusion.md, "Starting in motion: figures"): the LIO on a recording that
begins while the body moves, against LiDAR-only on the same recording and against the LIO started
at rest over the same stretch of motion.

For each profile, start and seed, the generator records `--duration` seconds from `--start` seconds
into the profile's motion (SimConfig.motion_start_s: a cut recording, a node restarted at speed),
and, as the reference, the whole motion from rest up to the end of that stretch, evaluated over the
stretch. The replay runs with a fixed 20 ms latency (the accuracy tables' model). Printed per run:
APE (aligned RMSE, m) and KITTI-style RPE (%) of the scan poses and of the 100 Hz odometry,
rotation RMSE (deg), registration failures, map restarts, re-initialisations, rejected LiDAR
groups, the first fused output after the first scan (s), how the filter was initialised and how far
its estimate of up was from the truth then and at the end; then the ratios the goal asks for (LIO /
LiDAR-only, LIO / standstill start), of the scan poses and of the 100 Hz odometry (against
LiDAR-only's scan poses, its only output).

  python figures/fusion_start_in_motion.py --profile racetrack --start 12 --duration 10 --seeds 1 2 3
  python figures/fusion_start_in_motion.py --profile urban --start 10 --duration 10 --seeds 1 2 3 --no-reference
"""

from __future__ import annotations

import argparse
import math
import sys

from farlio.simulation import LIDAR_MODELS, PROFILES, Recording, make_config, replay, stretch_accuracy
from fusion_imu_rates import racing_noise
from harness import FIXED_LATENCY_S, mode_overrides

COLUMNS = ["ape_m", "rpe_pct", "rot_deg", "odom_ape_m", "odom_rpe_pct", "failed", "map_restarts", "reinit"]
COLUMNS += ["rejected", "first_output_s"]


def fmt(v) -> str:
    return "-" if isinstance(v, float) and math.isnan(v) else (f"{v:.3f}" if isinstance(v, float) else str(v))


def describe_init(row: dict) -> str:
    i = row["initialization"]
    return (
        f"{i.mode} after {i.window_s:.2f} s ({i.window_poses} poses), speed {i.speed_m_s:.2f} m/s, map tilt "
        f"{i.map_tilt_deg:.2f} deg; up off by {row['initial_up_error_deg']:.3f} deg then, "
        f"{row['up_error_deg']:.3f} deg at the end; gravity norm error {100 * i.gravity_norm_error:.1f} %"
    )


def ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}" if b > 0 and math.isfinite(a) and math.isfinite(b) else "-"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--profile", choices=PROFILES, required=True)
    p.add_argument("--start", type=float, required=True, help="seconds into the profile's motion")
    p.add_argument("--duration", type=float, required=True, help="seconds recorded from there")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--imu-grade", default="profile")
    p.add_argument(
        "--racing-imu", action="store_true", help="the race car's IMU noise (figures/fusion_imu_rates.py's racing)"
    )
    p.add_argument("--lidar", choices=LIDAR_MODELS, default="profile", help="the LiDAR model (farlio simulate --lidar)")
    p.add_argument("--no-reference", action="store_true", help="without the run started at rest")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE")
    args = p.parse_args()
    print(
        f"{args.profile} ({args.lidar} LiDAR), {args.duration:g} s from {args.start:g} s into the motion; "
        f"columns: {' '.join(COLUMNS)}"
    )
    noise = racing_noise(args.profile) if args.racing_imu else {}
    for seed in args.seeds:
        cut = Recording(
            make_config(
                args.profile,
                seed=seed,
                duration_s=args.duration,
                motion_start_s=args.start,
                imu_grade=args.imu_grade,
                lidar=args.lidar,
                **noise,
            )
        )
        runs = {
            "LIO": stretch_accuracy(replay(cut, mode_overrides(args.overrides), fixed_latency_s=FIXED_LATENCY_S)),
            "LiDAR-only": stretch_accuracy(
                replay(cut, mode_overrides(args.overrides, "lidar-only"), fixed_latency_s=FIXED_LATENCY_S)
            ),
        }
        if not args.no_reference:
            whole = Recording(
                make_config(
                    args.profile,
                    seed=seed,
                    duration_s=args.start + args.duration,
                    imu_grade=args.imu_grade,
                    lidar=args.lidar,
                    **noise,
                )
            )
            ref_run = replay(whole, mode_overrides(args.overrides), fixed_latency_s=FIXED_LATENCY_S)
            runs["standstill start"] = stretch_accuracy(ref_run, from_s=args.start)
        print(f"seed {seed} (speed at the cut {cut.speed_at_start_m_s:.1f} m/s)")
        for name, row in runs.items():
            print(f"  {name:17s} " + " ".join(fmt(row.get(c, math.nan)) for c in COLUMNS))
            if "initialization" in row:
                print(f"  {'':17s} initialisation: {describe_init(row)}")
        lio, lo = runs["LIO"], runs["LiDAR-only"]
        line = f"  LIO/LiDAR-only APE {ratio(lio['ape_m'], lo['ape_m'])}, RPE {ratio(lio['rpe_pct'], lo['rpe_pct'])}"
        if "standstill start" in runs:
            ref = runs["standstill start"]
            line += (
                f", LIO/standstill APE {ratio(lio['ape_m'], ref['ape_m'])}, RPE {ratio(lio['rpe_pct'], ref['rpe_pct'])}"
            )
        print(line)
        # the 100 Hz output against LiDAR-only's scan poses (its only output) and the standstill start's
        line = (
            f"  100 Hz: LIO/LiDAR-only APE {ratio(lio['odom_ape_m'], lo['ape_m'])}, "
            f"RPE {ratio(lio['odom_rpe_pct'], lo['rpe_pct'])}"
        )
        if "standstill start" in runs:
            line += (
                f", LIO/standstill APE {ratio(lio['odom_ape_m'], ref['odom_ape_m'])}, "
                f"RPE {ratio(lio['odom_rpe_pct'], ref['odom_rpe_pct'])}"
            )
        print(line)
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
