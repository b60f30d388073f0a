#!/usr/bin/env python3
"""IMU rate, clock and noise (docs/fusion.md, "IMU rate and clock"): the LIO with the IMU at other
rates, off the scans' clock, noisier, or with samples missing, against the profile's own IMU and
LiDAR-only on the same scans.

IMUs: `profile`; `RATE` or `RATE:OFFSET` (Hz, and the offset of its samples from the scans' clock
in s); `racing` (the profile's rate with white noise of 3e-3 rad/s/sqrt(Hz) and 7e-2
m/s^2/sqrt(Hz), a vibrating race car's); `drop:N` (every N-th sample missing, a driver that drops
samples); `gap:START:LENGTH` (no sample for LENGTH s from START s). Per IMU and seed: APE (m),
KITTI-style RPE (%) and rotation RMSE (deg) of the scan poses, APE and RPE of the 100 Hz odometry,
LiDAR results rejected by the filter's gate and re-initialisations; the deterministic replay at a
fixed 20 ms latency (farlio.simulation.replay).

  python figures/fusion_imu_rates.py --profile urban --duration 30 --seeds 1 2 --imus 10 10:0.04 profile
  python figures/fusion_imu_rates.py --profile racetrack --duration 30 --seeds 1 2 \
      --imus profile racing drop:7 gap:15:0.5
"""

from __future__ import annotations

import argparse
import math

from farlio.simulation import IMU_GRADES, PROFILES, Recording, make_config, replay, stretch_accuracy
from harness import FIXED_LATENCY_S, LIDAR_ONLY

#: a vibrating race car's IMU: white noise densities (rad/s/sqrt(Hz), m/s^2/sqrt(Hz))
RACING_GYRO_DENSITY, RACING_ACCEL_DENSITY = 3e-3, 7e-2


def racing_noise(profile: str) -> dict[str, float]:
    """make_config's noise fields of the race car's IMU at the profile's IMU rate."""
    rate = make_config(profile).imu_rate_hz
    return {
        "gyro_noise_std_rad_s": RACING_GYRO_DENSITY * math.sqrt(rate),
        "accel_noise_std_m_s2": RACING_ACCEL_DENSITY * math.sqrt(rate),
    }


def recording(
    profile: str, seed: int, duration_s: float, imu: str, grade: str = "profile", lidar: str = "profile"
) -> Recording:
    """The profile's recording with the IMU `imu` (see the module's docstring) of `grade`, and the
    LiDAR model `lidar`."""
    kind, _, rest = imu.partition(":")
    base = {"seed": seed, "duration_s": duration_s, "lidar": lidar}
    if kind in ("profile", "drop", "gap"):
        rec = Recording(make_config(profile, imu_grade=grade, **base))
    elif kind == "racing":
        rec = Recording(make_config(profile, **base, **racing_noise(profile)))
    else:
        offset = float(rest or 0.0)
        rec = Recording(make_config(profile, imu_rate_hz=float(kind), imu_time_offset_s=offset, **base))
    if kind == "drop":
        every = int(rest)
        rec.imu = [s for i, s in enumerate(rec.imu) if i % every != every - 1]
    elif kind == "gap":
        start_s, length_s = (float(v) for v in rest.split(":"))
        t0 = rec.imu[0].stamp_ns
        rec.imu = [s for s in rec.imu if not (start_s <= (s.stamp_ns - t0) / 1e9 < start_s + length_s)]
    return rec


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
        "--imus",
        nargs="+",
        default=["10", "10:0.04", "profile"],
        help="IMUs: profile, RATE, RATE:OFFSET_S, racing, drop:N, gap:START_S:LENGTH_S",
    )
    p.add_argument("--imu-grade", choices=IMU_GRADES, default="profile", help="for profile, drop and gap")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="NAME=VALUE", help="config override")
    args = p.parse_args()
    print("columns: ape_m rpe_pct rot_deg odom_ape_m odom_rpe_pct rejected reinit")
    for seed in args.seeds:
        print(f"{args.profile} {args.duration:g} s, seed {seed}")
        lidar_only = None
        for imu in args.imus:
            rec = recording(args.profile, seed, args.duration, imu, args.imu_grade)
            lio = stretch_accuracy(replay(rec, args.overrides, fixed_latency_s=FIXED_LATENCY_S))
            print(row(f"LIO, IMU {imu}", lio), flush=True)
            if lidar_only is None:
                only = [*args.overrides, LIDAR_ONLY]
                lidar_only = stretch_accuracy(replay(rec, only, fixed_latency_s=FIXED_LATENCY_S))
                print(row("LiDAR-only", lidar_only), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
