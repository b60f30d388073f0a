"""`farlio latency-sweep`: APE of the LIO as the scan pipeline's latency grows (paper Fig. latency)."""

from __future__ import annotations

import argparse
from pathlib import Path

from farlio.ablation import latency_sweep
from farlio.cli_args import add_config_arguments, non_negative_float, positive_int
from farlio.config import load_config

DEFAULT_DELAYS_MS = [0, 20, 40, 60, 80, 100, 150, 200, 300]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("path", type=Path, help="a recording with IMU and ground truth")
    parser.add_argument("--out", type=Path, required=True, help="output folder: latency_sweep.csv/.md/.png")
    parser.add_argument(
        "--delays-ms",
        type=non_negative_float,
        nargs="+",
        default=DEFAULT_DELAYS_MS,
        help="delays added to the measured processing time (with --fixed: the latencies)",
    )
    parser.add_argument(
        "--fixed",
        action="store_true",
        help="each delay is the whole latency (the fixed latency model, no measured time): runs that repeat "
        "exactly, for comparing settings",
    )
    parser.add_argument("--max-frames", type=positive_int, default=None, help="stop each run after this many scans")
    parser.add_argument("--no-plot", action="store_true", help="no latency_sweep.png")
    add_config_arguments(parser)


def run(args: argparse.Namespace) -> int:
    rows = latency_sweep(
        args.path,
        args.out,
        [d / 1e3 for d in args.delays_ms],
        max_frames=args.max_frames,
        plot=not args.no_plot,
        config=load_config(args.config, args.overrides),
        fixed=args.fixed,
    )
    what = "latency" if args.fixed else "added"
    for r in rows:
        print(
            f"{what} {r['added_delay_ms']:6.0f} ms: APE {r['ape_m']:.3f} m, RPE {r['rpe_pct']:.3f} %, "
            f"dropped {r['dropped']}"
        )
    return 0
