"""`farlio simulate`: a LiDAR + IMU sequence with exact ground truth, in the sequence folder format."""

from __future__ import annotations

import argparse
from pathlib import Path

from farlio.cli_args import non_negative_float, non_negative_int, positive_float, probability
from farlio.progress import Progress
from farlio.simulation import IMU_GRADES, LIDAR_MODELS, PROFILES, make_config, write_sequence


def add_arguments(parser: argparse.ArgumentParser) -> None:
    _add_sequence_arguments(parser)
    _add_sensor_arguments(parser)
    _add_noise_arguments(parser)
    _add_output_arguments(parser)


def _add_sequence_arguments(parser: argparse.ArgumentParser) -> None:
    """The profile, where the sequence goes, its seed and which stretch of the motion it records."""
    parser.add_argument(
        "profile",
        choices=PROFILES,
        help="racetrack: 3 LiDARs at 20 Hz, up to 70 m/s, 800 Hz IMU; urban: 64-beam LiDAR at "
        "10 Hz, 8-15 m/s, 100 Hz IMU; handheld: 32-beam LiDAR at 10 Hz, rooms and corridors, "
        "200 Hz IMU; tunnel: the urban car's sensors, 0 -> 100 km/h through an 850 m tunnel whose bare "
        "middle is degenerate along the track (docs/simulation.md)",
    )
    parser.add_argument("--out", type=Path, required=True, help="output sequence folder (created)")
    parser.add_argument(
        "--seed", type=non_negative_int, default=1, help="noise seed (the scene and trajectory are fixed)"
    )
    parser.add_argument(
        "--duration",
        type=positive_float,
        default=None,
        help="seconds to generate (default: the profile's, docs/simulation.md)",
    )
    parser.add_argument(
        "--start",
        type=non_negative_float,
        default=0.0,
        metavar="S",
        help="begin the sequence S seconds into the profile's motion (default 0: at its start, at rest); later "
        "starts record a body already moving, as a cut recording or a node restarted at speed does",
    )


def _add_sensor_arguments(parser: argparse.ArgumentParser) -> None:
    """The LiDAR model and the sensors' rates."""
    parser.add_argument(
        "--lidar",
        choices=LIDAR_MODELS,
        default="profile",
        help="profile: the profile's own LiDARs (default); one sensor of a model in their place, where the "
        "first one is mounted: avia (Livox Avia class, forward 70x77 deg non-repetitive rosette, 240k points/s), "
        "mid360 (Livox Mid-360 class, 360x59 deg non-repetitive, 200k points/s), vlp16, hdl32, os128 (spinning "
        "16, 32, 128 beams) (docs/simulation.md)",
    )
    parser.add_argument(
        "--lidar-rate",
        type=positive_float,
        default=None,
        metavar="HZ",
        help="scans per second (default: the profile's)",
    )
    parser.add_argument(
        "--imu-rate",
        type=positive_float,
        default=None,
        metavar="HZ",
        help="IMU samples per second (default: the profile's; 10 Hz is KITTI raw's OXTS rate)",
    )
    parser.add_argument(
        "--imu-offset",
        type=non_negative_float,
        default=0.0,
        metavar="S",
        help="the IMU's samples fall S seconds after the whole IMU periods of the sequence clock (default 0; below "
        "one IMU period), as an IMU that is not phase-locked to the LiDAR",
    )


def _add_noise_arguments(parser: argparse.ArgumentParser) -> None:
    """The sensors' errors: none, a datasheet IMU grade, or single noise levels."""
    parser.add_argument("--noise-free", action="store_true", help="exact ranges, no dropout, IMU without noise/bias")
    parser.add_argument(
        "--imu-grade",
        choices=IMU_GRADES,
        default="profile",
        help="profile: the profile's IMU noise (default, unchanged); ideal: no IMU error; consumer (BMI088/"
        "ICM-42688 class), industrial (ADIS16470/MTi-630 class), tactical (HG4930 class): turn-on bias, bias "
        "walk, white noise, scale factor, misalignment, g-sensitivity and speed-dependent vibration "
        "(docs/simulation.md)",
    )
    parser.add_argument(
        "--no-vibration", action="store_true", help="with a datasheet --imu-grade: leave out the platform vibration"
    )
    parser.add_argument("--range-noise", type=non_negative_float, default=None, metavar="M", help="range noise std (m)")
    parser.add_argument("--dropout", type=probability, default=None, metavar="P", help="chance a ray returns nothing")
    parser.add_argument(
        "--gyro-noise", type=non_negative_float, default=None, metavar="RAD_S", help="gyro white noise std"
    )
    parser.add_argument(
        "--accel-noise", type=non_negative_float, default=None, metavar="M_S2", help="accel white noise std"
    )


def _add_output_arguments(parser: argparse.ArgumentParser) -> None:
    """The files written besides the sequence folder, and progress."""
    parser.add_argument(
        "--kitti",
        action="store_true",
        help="also write the KITTI odometry layout: velodyne/*.bin (motion-compensated to the scan end) + times.txt",
    )
    parser.add_argument(
        "--encoding",
        default="binary",
        choices=["ascii", "binary", "binary_compressed"],
        help="PCD encoding of lidar/*.pcd",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    cfg = make_config(
        args.profile,
        seed=args.seed,
        duration_s=args.duration,
        motion_start_s=args.start,
        noise_free=args.noise_free,
        imu_grade=args.imu_grade,
        vibration=not args.no_vibration,
        lidar=args.lidar,
        lidar_rate_hz=args.lidar_rate,
        imu_rate_hz=args.imu_rate,
        imu_time_offset_s=args.imu_offset,
        range_noise_std_m=args.range_noise,
        dropout_probability=args.dropout,
        gyro_noise_std_rad_s=args.gyro_noise,
        accel_noise_std_m_s2=args.accel_noise,
    )
    bar = Progress(0, f"simulate {args.profile}", False if args.no_progress else None)

    def on_scan(done: int, total: int) -> None:
        bar.total = total
        bar.update(done)

    stats = write_sequence(cfg, args.out, kitti=args.kitti, encoding=args.encoding, on_scan=on_scan)
    bar.close()
    print(
        f"{args.profile}: {stats['scans']} scans of {stats['points_per_scan']:.0f} points on average, "
        f"{1e3 * stats['generation_s_per_scan']:.1f} ms to generate a scan; written to {args.out}"
    )
    return 0
