"""`farlio ros2-play`: publishes a recording (any format `farlio run` reads) as ROS 2 topics."""

from __future__ import annotations

import argparse
from pathlib import Path

from farlio.cli_args import non_negative_float
from farlio.datasets import FORMAT_HELP, FORMATS, LoadOptions, open_dataset
from farlio.datasets.cut import StartCut
from farlio.datasets.pointcloud2_encode import CONVENTIONS
from farlio.ros2 import WAIT_SUBSCRIBERS_S, add_transport_argument, choose_transport, require_rclpy


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("path", type=Path, help=f"the recording: {FORMAT_HELP}")
    parser.add_argument("--format", default="auto", choices=["auto", *FORMATS], help="input format")
    parser.add_argument("--rate", type=float, default=1.0, help="playback speed, times real time")
    parser.add_argument(
        "--lidar-topic",
        dest="lidar_topics",
        action="append",
        default=[],
        metavar="TOPIC",
        help="PointCloud2 topic to publish (default /points); repeated: each scan is split by azimuth "
        "into one sector per topic (several LiDARs in one frame)",
    )
    parser.add_argument("--imu-topic", default="/imu", help="Imu topic to publish ('none': no IMU)")
    parser.add_argument("--lidar-frame", default="lidar", help="frame_id of the clouds")
    parser.add_argument("--imu-frame", default="imu", help="frame_id of the IMU samples")
    parser.add_argument(
        "--convention",
        default="ouster",
        choices=list(CONVENTIONS),
        help="per-point time field of the clouds, as this driver writes it",
    )
    parser.add_argument(
        "--lidar-time-shift",
        type=float,
        default=0.0,
        metavar="S",
        help="add S seconds to every LiDAR stamp (a LiDAR clock off the IMU clock; the node's "
        "time_offset_s = -S undoes it)",
    )
    parser.add_argument(
        "--wait-subscribers",
        type=float,
        default=WAIT_SUBSCRIBERS_S,
        metavar="S",
        help="wait up to S seconds for a subscriber on every topic before playing (what is published "
        "before a subscriber is discovered is lost to it; 0: do not wait)",
    )
    parser.add_argument(
        "--start",
        type=non_negative_float,
        default=0.0,
        metavar="S",
        help="skip the recording's first S seconds (as farlio run --start): a node that starts while the vehicle "
        "moves, or one restarted mid-run",
    )
    parser.add_argument("--max-scans", type=int, default=None, help="stop after this many scans")
    parser.add_argument("--clock", action="store_true", help="also publish /clock at the IMU stamps (use_sim_time)")
    add_transport_argument(parser)
    rec = parser.add_argument_group("recordings with several topics (bags)")
    rec.add_argument("--in-lidar-topic", dest="in_lidar_topics", action="append", default=[], metavar="TOPIC")
    rec.add_argument("--in-imu-topic", default=None, metavar="TOPIC")
    rec.add_argument("--calib", type=Path, default=None, metavar="YAML", help="extrinsics of the recording")


def run(args: argparse.Namespace) -> int:
    require_rclpy()
    transport = choose_transport(args.transport)
    from farlio.ros2.play import PlayOptions, play

    if args.rate <= 0:
        raise ValueError(f"--rate {args.rate}: expected > 0")
    options = LoadOptions(lidar_topics=list(args.in_lidar_topics), imu_topic=args.in_imu_topic, calib=args.calib)
    dataset = open_dataset(args.path, args.format, options)
    if args.start > 0.0:
        dataset = StartCut(dataset, args.start)
    stats = play(
        dataset,
        PlayOptions(
            lidar_topics=list(args.lidar_topics) or ["/points"],
            imu_topic="" if args.imu_topic == "none" else args.imu_topic,
            lidar_frame=args.lidar_frame,
            imu_frame=args.imu_frame,
            convention=args.convention,
            rate=args.rate,
            lidar_time_shift_s=args.lidar_time_shift,
            wait_subscribers_s=args.wait_subscribers,
            max_scans=args.max_scans,
            clock=args.clock,
        ),
        args.ros_args,
    )
    print(f"transport: {transport}")
    print(
        f"published {stats.scans} scans ({stats.clouds} clouds) and {stats.imu} IMU samples in {stats.wall_s:.1f} s; "
        f"at most {stats.late_s * 1000:.1f} ms late"
    )
    return 0
