"""`farlio bench`: whole-frame latency of farlio's scan pipeline next to KISS-ICP, same scans, same run,
with farlio's stages, work and memory; each data set once per thread count."""

from __future__ import annotations

import argparse
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from farlio.benchmark import compare, format_table, generated_scans, lidar_poses
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
        help="also a recording (any format farlio run reads; repeatable); where it has the true poses at its "
        "scans (a sequence folder's groundtruth_scans.tum), both systems' APE and RPE against them",
    )
    parser.add_argument(
        "--threads",
        type=non_negative_int,
        nargs="+",
        metavar="N",
        default=[0],
        help="threads for both systems (0: all); several values benchmark each data set once per value, "
        "keyed '<data set> threads=<n>' in bench.json",
    )
    parser.add_argument(
        "--device",
        choices=DEVICES,
        default="auto",
        help="farlio's backend: auto (the GPU when present, else the CPU with a message), cpu, cuda",
    )
    parser.add_argument(
        "--rounds",
        type=positive_int,
        default=1,
        help="passes over each data set, farlio and KISS-ICP in turns, each pass with a new pipeline; the "
        "frames of all passes are pooled (a machine whose load comes and goes then weighs on both alike) "
        "and each pass's ratio of the medians is printed",
    )
    parser.add_argument("--no-kiss", action="store_true", help="farlio only (KISS-ICP: pip install kiss-icp)")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for bench.json (optional): latency, stages_ms, work, memory, accuracy per data set",
    )


def _data_sets(args: argparse.Namespace) -> Iterator[tuple[str, list[Any], Any]]:
    """(name, scans, ground truth or None) of each generated profile, then of each recording."""
    for profile in args.profile or ([] if args.data else ["urban"]):
        scans, gt, _ = generated_scans(profile, args.scans)
        yield profile, scans, gt
    for path in args.data:
        ds = open_dataset(path)
        yield str(path), [ds.scan(i) for i in range(min(len(ds), args.scans))], _lidar_groundtruth(ds)


def _lidar_groundtruth(ds: Any) -> Any:
    """The recording's true LiDAR poses at its scan ends, or None without a ground truth at the scans."""
    body = ds.groundtruth_scans()
    return None if body is None else lidar_poses(body, ds.T_imu_lidar())


def result_key(name: str, threads: int, several: bool) -> str:
    """bench.json's key of a data set: its name, with the thread count when several were asked for."""
    return f"{name} threads={threads}" if several else name


def run(args: argparse.Namespace) -> int:
    results = {}
    thread_counts = list(dict.fromkeys(args.threads))  # each count once, in the order given
    for name, scans, gt in _data_sets(args):
        for threads in thread_counts:
            key = result_key(name, threads, len(thread_counts) > 1)
            results[key] = compare(
                scans, gt, threads=threads, with_kiss=not args.no_kiss, device=args.device, rounds=args.rounds
            )
            print(format_table(name, results[key]), flush=True)
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "bench.json").write_text(json.dumps(results, indent=2))
    return 0
