"""`farlio run`: odometry over a recording, with trajectories, timings and a summary in --out."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from farlio.cli_args import add_config_arguments, non_negative_float, non_negative_int, positive_float, positive_int
from farlio.config import load_config
from farlio.datasets import FORMAT_HELP, FORMATS, LoadOptions, TimeOptions, open_dataset
from farlio.datasets.cut import StartCut
from farlio.datasets.pointcloud2 import HEADER_STAMPS, TIME_FIELDS, TIME_UNITS
from farlio.mapping import MapOptions
from farlio.runner import DEVICES, format_summary, replay_options, run_dataset


def add_arguments(parser: argparse.ArgumentParser) -> None:
    _add_input_arguments(parser)
    _add_recording_arguments(parser)
    _add_latency_arguments(parser)
    _add_map_arguments(parser)
    _add_output_arguments(parser)


def _add_input_arguments(parser: argparse.ArgumentParser) -> None:
    """The recording, the output folder, the parameter set, the backend and which part of the recording runs."""
    parser.add_argument("path", type=Path, help=f"the recording, its format detected from the path: {FORMAT_HELP}")
    parser.add_argument("--out", type=Path, required=True, help="output folder (created)")
    parser.add_argument("--format", default="auto", choices=["auto", *FORMATS], help="input format")
    add_config_arguments(parser)
    parser.add_argument(
        "--threads", type=non_negative_int, default=None, help="CPU threads (default: all; = num_threads)"
    )
    parser.add_argument(
        "--device",
        choices=DEVICES,
        default=None,
        help="scan pipeline backend (= the config field device, default auto): auto takes the GPU "
        "when one is present and falls back to the CPU with a message; cuda without one is an error",
    )
    parser.add_argument("--max-frames", type=positive_int, default=None, help="stop after this many scans")
    parser.add_argument(
        "--start",
        type=non_negative_float,
        default=0.0,
        metavar="S",
        help="skip the recording's first S seconds (from its first scan's start): the run begins with the first "
        "scan that starts then, with the IMU from then on, as a recording cut there would (the vehicle may be "
        "moving: the filter then initialises in motion, summary.json initialization)",
    )
    parser.add_argument(
        "--gt",
        type=Path,
        default=None,
        help="ground-truth body poses (TUM) to evaluate against; a sequence folder's "
        "groundtruth_scans.tum (MulRan: global_pose.csv; KITTI layout: groundtruth_kitti.txt) is used by default",
    )


def _add_recording_arguments(parser: argparse.ArgumentParser) -> None:
    """How a bag's or an Ouster recording's topics, calibration and point times are read."""
    rec = parser.add_argument_group("recordings (bags, Ouster, calibration)")
    rec.add_argument(
        "--lidar-topic",
        dest="lidar_topics",
        action="append",
        default=[],
        metavar="TOPIC",
        help="PointCloud2 topic of a bag (or Ouster lidar_packets topic); repeat it to merge several "
        "LiDARs into one scan per period of the first; not given: the bag's only PointCloud2 topic",
    )
    rec.add_argument(
        "--imu-topic",
        default=None,
        metavar="TOPIC",
        help="sensor_msgs/Imu topic of a bag ('none': LiDAR-only); not given: the bag's only Imu topic",
    )
    rec.add_argument(
        "--calib",
        type=Path,
        default=None,
        metavar="YAML",
        help="extrinsics file with T_imu_lidar (4x4, or {topic: 4x4} for several LiDARs); overrides "
        "/tf_static and the recording's own calibration",
    )
    rec.add_argument(
        "--meta",
        type=Path,
        default=None,
        metavar="JSON",
        help="Ouster sensor metadata; not given: the .pcap's name with .json, or the bag's metadata topic",
    )
    rec.add_argument(
        "--time-field",
        default="auto",
        metavar="NAME",
        help=f"PointCloud2 per-point time field ('auto': first of {', '.join(TIME_FIELDS)}; "
        f"'none': no per-point time, no undistortion)",
    )
    rec.add_argument(
        "--time-unit",
        default="auto",
        choices=TIME_UNITS,
        help="unit of the time field ('auto': float fields in s, integer fields in ns)",
    )
    rec.add_argument(
        "--header-stamp",
        default="auto",
        choices=HEADER_STAMPS,
        help="whether a cloud's header stamp is its scan start or end ('auto': end when all "
        "relative point times are <= 0, else start)",
    )
    rec.add_argument("--no-imu", action="store_true", help="ignore the recording's IMU: LiDAR-only odometry")


def _add_latency_arguments(parser: argparse.ArgumentParser) -> None:
    """When a scan's result reaches the fusion in the replay."""
    parser.add_argument(
        "--latency",
        default="measured",
        choices=["measured", "zero", "fixed"],
        help="replay latency model: a scan's result reaches the fusion after its measured "
        "processing time, at once, or after --fixed-latency",
    )
    parser.add_argument(
        "--fixed-latency", type=non_negative_float, default=0.0, metavar="S", help="latency with --latency fixed"
    )
    parser.add_argument(
        "--added-delay",
        type=non_negative_float,
        default=0.0,
        metavar="S",
        help="extra delay added to every result (latency sweeps)",
    )


def _add_map_arguments(parser: argparse.ArgumentParser) -> None:
    """The saved map, loop closure and localization in a prior map."""
    maps = parser.add_argument_group("maps")
    maps.add_argument(
        "--save-map",
        action="store_true",
        help="write the whole map (every scan whose pose was used, not only the submap around the sensor; one "
        "centroid with the mean intensity per cell of --map-resolution) in the world frame of the poses as "
        "map.pcd and map.ply, and map.png (top view coloured by height, the trajectory on top)",
    )
    maps.add_argument(
        "--map-resolution",
        type=positive_float,
        default=None,
        metavar="M",
        help="cell of the saved map in metres (= map.export_resolution_m; default: the map's point spacing, "
        "voxel_size_m / sqrt(max_points_per_voxel))",
    )
    maps.add_argument(
        "--loop-closure",
        action="store_true",
        help="close loops (needs pip install 'farlio[mapping]'): keyframes every loop.keyframe_distance_m, "
        "revisited places found near the current global estimate and verified by GICP (overlap, ambiguity), "
        "a pose graph optimised with gtsam; writes scans_lidar_global.tum, scans_body_global.tum and loops.csv "
        "(with --save-map also map_global.pcd/.ply/.png); the odometry's outputs are unchanged (docs/maps.md)",
    )
    maps.add_argument(
        "--prior-map",
        type=Path,
        default=None,
        metavar="MAP",
        help="localize in this map (a map.pcd or map.ply of --save-map, or any point cloud in one frame) instead "
        "of building one: the submap is the prior map held fixed, poses are in its frame; a scan matching less "
        "than localization.min_inlier_fraction of its points is lost (timing.csv lost) and keeps its prediction; "
        "exit status 3 when the run was not localized (lost in half of its scans or more)",
    )
    maps.add_argument(
        "--initial-pose",
        type=float,
        nargs=6,
        default=None,
        metavar=("X", "Y", "Z", "ROLL", "PITCH", "YAW"),
        help="body pose at the first scan in the map's frame (metres, degrees; default: the origin, i.e. where "
        "the mapping run started); with an IMU roll and pitch come from gravity",
    )


def _add_output_arguments(parser: argparse.ArgumentParser) -> None:
    """Plots, progress and the live view."""
    parser.add_argument("--no-plot", action="store_true", help="do not write trajectory.png, latency.png and eval.png")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument(
        "--view",
        action="store_true",
        help="live 3D view with rerun-sdk (pip install rerun-sdk); without a display the view is "
        "saved as run.rrd in --out",
    )


def load_options(args: argparse.Namespace) -> LoadOptions:
    return LoadOptions(
        lidar_topics=list(args.lidar_topics),
        imu_topic=args.imu_topic,
        calib=args.calib,
        meta=args.meta,
        time=TimeOptions(args.time_field, args.time_unit, args.header_stamp),
    )


def run(args: argparse.Namespace) -> int:
    overrides = list(args.overrides)
    if args.threads is not None:
        overrides.append(f"num_threads={args.threads}")
    if args.device is not None:
        overrides.append(f"device={args.device}")
    config = load_config(args.config, overrides)
    viewer = None
    if args.view:
        from farlio.viewer import RerunViewer

        args.out.mkdir(parents=True, exist_ok=True)
        viewer = RerunViewer(args.out)
        print(f"live view: {viewer.where}")
    dataset = open_dataset(args.path, args.format, load_options(args))
    if args.start > 0.0:
        dataset = StartCut(dataset, args.start)
    summary = run_dataset(
        dataset,
        args.out,
        config,
        max_frames=args.max_frames,
        maps=MapOptions(args.save_map, args.map_resolution, args.prior_map, args.initial_pose, args.loop_closure),
        groundtruth=args.gt,
        progress=False if args.no_progress else None,
        plot=not args.no_plot,
        use_imu=not args.no_imu,
        on_frame=viewer,
        options=replay_options(args.latency, args.fixed_latency, args.added_delay),
    )
    print(format_summary(summary))
    print(f"outputs in {args.out}")
    return _localization_status(summary)


#: the exit status of a run in a prior map that was lost in half of its scans or more
EXIT_NOT_LOCALIZED = 3


def _localization_status(summary: dict) -> int:
    """Warns when scans were lost in the prior map; EXIT_NOT_LOCALIZED when the run was lost in
    half of its scans or more (a wrong map or initial pose)."""
    loc = summary.get("localization")
    if not loc or not loc["frames_lost"]:
        return 0
    if not loc["localized"]:
        print(
            f"farlio: error: not localized in {loc['prior_map']}: {loc['frames_lost']} of "
            f"{loc['frames_lost'] + loc['frames_localized']} scans did not match it (is the map of this place, and "
            "--initial-pose right?)",
            file=sys.stderr,
        )
        return EXIT_NOT_LOCALIZED
    print(
        f"farlio: warning: {loc['frames_lost']} of {loc['frames_lost'] + loc['frames_localized']} scans did not "
        "match the prior map (timing.csv lost); their poses are predictions",
        file=sys.stderr,
    )
    return 0
