"""`farlio bench`: whole-frame latency of farlio's scan pipeline next to KISS-ICP, same scans, same run."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from farlio.benchmark import compare, format_table, generated_scans
from farlio.cli_args import non_negative_int, positive_int
from farlio.datasets import open_dataset
from farlio.runner import DEVICES
from farlio.simulation import PROFILES


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--profile",
        action="append",
        choices=PROFILES,
        help="generated scans of this profile (repeatable; default: urban)",
    )
    parser.add_argument("--scans", type=positive_int, default=100, help="frames per data set")
    parser.add_argument(
        "--data",
        type=Path,
        action="append",
        default=[],
        help="also a recording (any format farlio run reads; repeatable)",
    )
    parser.add_argument("--threads", type=non_negative_int, default=0, help="threads for both systems (0: all)")
    parser.add_argument(
        "--device",
        choices=DEVICES,
        default="auto",
        help="farlio's backend: auto (the GPU when present, else the CPU with a message), cpu, cuda",
    )
    parser.add_argument("--no-kiss", action="store_true", help="farlio only (KISS-ICP: pip install kiss-icp)")
    parser.add_argument("--out", type=Path, default=None, help="folder for bench.json (optional)")


def run(args: argparse.Namespace) -> int:
    results = {}
    for profile in args.profile or ([] if args.data else ["urban"]):
        scans, gt, _ = generated_scans(profile, args.scans)
        results[profile] = compare(scans, gt, threads=args.threads, with_kiss=not args.no_kiss, device=args.device)
        print(format_table(profile, results[profile]), flush=True)
    for path in args.data:
        ds = open_dataset(path)
        scans = [ds.scan(i) for i in range(min(len(ds), args.scans))]
        results[str(path)] = compare(scans, None, threads=args.threads, with_kiss=not args.no_kiss, device=args.device)
        print(format_table(str(path), results[str(path)]), flush=True)
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "bench.json").write_text(json.dumps(results, indent=2))
    return 0
