#!/usr/bin/env python3
"""IMU rate and clock (docs/fusion.md, "IMU rate and clock"): the LIO with the IMU at other rates
and off the scans' clock, against the profile's own IMU and LiDAR-only on the same scans.

Per IMU (rate in Hz, and the offset of its samples from the scans' clock in s) and seed: APE (m),
KITTI-style RPE (%) and rotation RMSE (deg) of the scan poses, APE and RPE of the 100 Hz odometry,
LiDAR results rejected by the filter's gate and re-initialisations; the deterministic replay at a
fixed 20 ms latency (farlio.simulation.replay).

  python figures/fusion_imu_rates.py --profile urban --duration 30 --seeds 1 2 --imus 10 10:0.04 profile
"""

from __future__ import annotations

import argparse

from farlio.simulation import PROFILES, Recording, make_config, replay, stretch_accuracy
from harness import FIXED_LATENCY_S, LIDAR_ONLY


def parse_imu(text: str) -> tuple[float | None, float]:
    """'profile', 'RATE' or 'RATE:OFFSET' -> (rate or None for the profile's, offset s)."""
    if text == "profile":
        return None, 0.0
    rate, _, offset = text.partition(":")
    return float(rate), float(offset or 0.0)


def row(label: str, a: dict) -> str:
    return (
        f"  {label:26s} {a['ape_m']:.4f} {a['rpe_pct']:.3f} {a['rot_deg']:.3f} {a['odom_ape_m']:.4f} "
        f"{a['odom_rpe_pct']:.3f} {a.get('rejected', '-')} {a.get('reinit', '-')}"
    )


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--profile", choices=PROFILES, default="urban")
    p.add_argument("--duration", type=float, default=30.0, help="seconds from a standstill")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    p.add_argument(
        "--imus", nargs="+", default=["10", "10:0.04", "profile"], help="IMUs: 'profile', RATE or RATE:OFFSET_S"
    )
    args = p.parse_args()
    print("columns: ape_m rpe_pct rot_deg odom_ape_m odom_rpe_pct rejected reinit")
    for seed in args.seeds:
        print(f"{args.profile} {args.duration:g} s, seed {seed}")
        lidar_only = None
        for imu in args.imus:
            rate, offset = parse_imu(imu)
            rec = Recording(
                make_config(
                    args.profile, seed=seed, duration_s=args.duration, imu_rate_hz=rate, imu_time_offset_s=offset
                )
            )
            print(
                row(f"LIO, IMU {imu}", stretch_accuracy(replay(rec, [], fixed_latency_s=FIXED_LATENCY_S))), flush=True
            )
            if lidar_only is None:
                lidar_only = stretch_accuracy(replay(rec, [LIDAR_ONLY], fixed_latency_s=FIXED_LATENCY_S))
                print(row("LiDAR-only", lidar_only), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
