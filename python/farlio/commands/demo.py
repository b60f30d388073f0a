"""`farlio demo`: the LiDAR-inertial odometry on a generated sequence served from memory, with its
whole map saved and the accuracy against the exact ground truth: `farlio simulate` followed by
`farlio run --save-map`, without writing the scans (45 s of the urban drive is 1.1 GB of PCD; the
demo's outputs are a few MB)."""

from __future__ import annotations

import argparse
from pathlib import Path

from farlio.cli_args import non_negative_int, positive_float
from farlio.config import load_config
from farlio.datasets.generated import GeneratedDataset
from farlio.mapping import MapOptions
from farlio.runner import format_summary, run_dataset
from farlio.simulation import PROFILES

#: the embedded default: about 430 m down a street and round a corner
DEFAULT_PROFILE = "urban"
DEFAULT_DURATION_S = 45.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--out", type=Path, required=True, help="output folder (created): farlio run's files and the ground truth"
    )
    parser.add_argument("--profile", choices=PROFILES, default=DEFAULT_PROFILE, help="the generator's profile")
    parser.add_argument("--duration", type=positive_float, default=DEFAULT_DURATION_S, help="seconds of motion")
    parser.add_argument("--seed", type=non_negative_int, default=1, help="noise seed")
    parser.add_argument("--no-plot", action="store_true", help="no trajectory, latency and map images")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    dataset = GeneratedDataset(args.profile, args.seed, args.duration, args.out / "groundtruth", body_groundtruth=True)
    summary = run_dataset(
        dataset,
        args.out,
        load_config(None, []),
        maps=MapOptions(save=True),
        progress=False if args.no_progress else None,
        plot=not args.no_plot,
    )
    print(format_summary(summary))
    print(f"outputs in {args.out}")
    return 0
