"""`farlio run`: odometry over a recording, with trajectories, timings and a summary in --out."""
from __future__ import annotations

import argparse
from pathlib import Path

from farlio.config import load_config
from farlio.datasets import FORMATS, open_dataset
from farlio.runner import DEVICES, format_summary, replay_options, run_dataset


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("path", type=Path, help="the recording: a sequence folder, a KITTI sequence folder "
                        "(velodyne/ + times.txt) or a folder of .pcd/.ply/.bin scans")
    parser.add_argument("--out", type=Path, required=True, help="output folder (created)")
    parser.add_argument("--format", default="auto", choices=["auto", *FORMATS], help="input format")
    parser.add_argument("--config", type=Path, default=None, help="YAML file overriding config fields")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override one config field, e.g. --set map.voxel_size_m=2 (repeatable)")
    parser.add_argument("--threads", type=int, default=None, help="CPU threads (default: all; = num_threads)")
    parser.add_argument("--device", choices=DEVICES, default=None,
                        help="scan pipeline backend (= the config field device, default auto): auto takes the GPU "
                             "when one is present and falls back to the CPU with a message; cuda without one is an error")
    parser.add_argument("--max-frames", type=int, default=None, help="stop after this many scans")
    parser.add_argument("--gt", type=Path, default=None,
                        help="ground-truth body poses (TUM) to evaluate against; a sequence folder's "
                             "groundtruth_scans.tum is used by default")
    parser.add_argument("--latency", default="measured", choices=["measured", "zero", "fixed"],
                        help="replay latency model: a scan's result reaches the fusion after its measured "
                             "processing time, at once, or after --fixed-latency")
    parser.add_argument("--fixed-latency", type=float, default=0.0, metavar="S", help="latency with --latency fixed")
    parser.add_argument("--added-delay", type=float, default=0.0, metavar="S",
                        help="extra delay added to every result (latency sweeps)")
    parser.add_argument("--save-map", action="store_true", help="write the final submap as map.ply")
    parser.add_argument("--no-plot", action="store_true", help="do not write eval.png")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    overrides = list(args.overrides)
    if args.threads is not None:
        overrides.append(f"num_threads={args.threads}")
    if args.device is not None:
        overrides.append(f"device={args.device}")
    config = load_config(args.config, overrides)
    dataset = open_dataset(args.path, args.format)
    summary = run_dataset(dataset, args.out, config, max_frames=args.max_frames, save_map=args.save_map,
                          groundtruth=args.gt, progress=False if args.no_progress else None,
                          plot=not args.no_plot,
                          options=replay_options(args.latency, args.fixed_latency, args.added_delay))
    print(format_summary(summary))
    print(f"outputs in {args.out}")
    return 0
