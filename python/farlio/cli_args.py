"""Arguments shared by the commands: numbers that must lie in a range, and the config fields.

argparse reports a value they refuse as ``farlio <command>: error: argument --max-frames: must be
an integer >= 1, got -1`` with exit status 2, before any work starts.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path


def _number(kind: type, text: str) -> float | int:
    try:
        value = kind(text)
    except ValueError:
        name = "an integer" if kind is int else "a number"
        raise argparse.ArgumentTypeError(f"must be {name}, got {text!r}") from None
    if isinstance(value, float) and not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def _bounded(kind: type, low: float, *, inclusive: bool = True, high: float | None = None) -> Callable[[str], float]:
    name = "an integer" if kind is int else "a number"
    bound = f">= {low:g}" if inclusive else f"> {low:g}"
    what = f"{name} {bound}" if high is None else f"{name} in [{low:g}, {high:g}]"

    def parse(text: str):
        value = _number(kind, text)
        if (value < low if inclusive else value <= low) or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"must be {what}, got {text}")
        return value

    parse.__name__ = what  # argparse names the type in some messages
    return parse


#: a count of at least one (frames, scans, steps)
positive_int = _bounded(int, 1)
#: 0 or more (threads, where 0 means all)
non_negative_int = _bounded(int, 0)
#: a finite number > 0 (durations, distances, rates)
positive_float = _bounded(float, 0.0, inclusive=False)
#: a finite number >= 0 (tolerances, delays, noise levels)
non_negative_float = _bounded(float, 0.0)
#: a chance in [0, 1]
probability = _bounded(float, 0.0, high=1.0)


def add_config_arguments(parser: argparse.ArgumentParser) -> None:
    """--config YAML and --set KEY=VALUE (repeatable): the config fields a command runs with
    (farlio.config.load_config(args.config, args.overrides))."""
    parser.add_argument("--config", type=Path, default=None, help="YAML file overriding config fields")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override one config field, e.g. --set map.voxel_size_m=2 (repeatable)",
    )
