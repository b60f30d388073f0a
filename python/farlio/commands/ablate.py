"""`farlio ablate`: the paper's component ablation (EKF, DC, MU, SA GICP, ASMD) on one recording."""

from __future__ import annotations

import argparse
from pathlib import Path

from farlio.ablation import ABLATION_ROWS, ablate
from farlio.cli_args import positive_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("path", type=Path, help="a recording with IMU and ground truth (e.g. farlio simulate output)")
    parser.add_argument("--out", type=Path, required=True, help="output folder: ablation.csv/.md and one run per row")
    parser.add_argument("--latency", default="measured", choices=["measured", "zero"], help="replay latency model")
    parser.add_argument("--max-frames", type=positive_int, default=None, help="stop each run after this many scans")


def run(args: argparse.Namespace) -> int:
    rows = ablate(args.path, args.out, latency=args.latency, max_frames=args.max_frames)
    print(f"{'components':20s} {'APE m':>9s} {'RPE %':>8s} {'dropped':>8s}")
    for r in rows:
        print(f"{r['components']:20s} {r['ape_m']:9.3f} {r['rpe_pct']:8.3f} {r['dropped']:8d}")
    print(f"{len(ABLATION_ROWS)} runs in {args.out}")
    return 0
