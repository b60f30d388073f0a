"""The `farlio` command line tool: one entry point, one subcommand per job.

Every subcommand that writes files takes ``--out DIR``; ``farlio <command> --help`` documents
every option.
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import warnings

# name -> (module, help). Each module provides add_arguments(parser) and run(args) -> int.
COMMANDS = {
    "run": ("farlio.commands.run", "run the odometry over a recording and write trajectories, timings, summary"),
    "simulate": ("farlio.commands.simulate", "generate a LiDAR + IMU sequence with exact ground truth"),
    "demo": (
        "farlio.commands.demo",
        "the LIO on a generated sequence served from memory (no scans on disk), its map and its accuracy",
    ),
    "eval": ("farlio.commands.evaluate", "compare a trajectory with ground truth (APE, RPE, coverage)"),
    "ablate": ("farlio.commands.ablate", "component ablation (EKF, DC, MU, SA GICP, ASMD) on a recording"),
    "latency-sweep": ("farlio.commands.latency_sweep", "APE as the pipeline latency grows (added delays)"),
    "bench": (
        "farlio.commands.bench",
        "whole-frame latency next to KISS-ICP on the same scans; farlio's stages, work and memory",
    ),
    "ros2": ("farlio.commands.ros2", "the ROS 2 node: live IMU and PointCloud2 topics in, odometry out (.venv-ros)"),
    "ros2-play": (
        "farlio.commands.ros2_play",
        "publish a recording as ROS 2 topics, in real time or faster (.venv-ros)",
    ),
    "config": (
        "farlio.commands.config",
        "print the essential parameters (--all: every one) with their defaults and meaning (YAML)",
    ),
    "info": ("farlio.commands.info", "print the build (CUDA backend, devices) and version"),
}


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="farlio",
        description="farlio: fast, accurate, robust LiDAR-inertial odometry.",
    )
    sub = parser.add_subparsers(dest="command", metavar="<command>", required=True)
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(
            name, help=help_text, description=help_text, formatter_class=argparse.ArgumentDefaultsHelpFormatter
        )
        importlib.import_module(module).add_arguments(p)
        p.set_defaults(_module=module)
    return parser


#: where ROS 2 arguments start (`farlio ros2 --ros-args -p name:=value`): the rest goes to rclpy
ROS_ARGS = "--ros-args"
ROS_COMMANDS = ("ros2", "ros2-play")


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:  # noqa: ARG001
    """Warnings of the library (e.g. a trajectory reader skipping a torn last line) as one line
    "farlio: warning: ..." on stderr, like the CLI's own warnings, not as Python source locations."""
    print(f"farlio: warning: {message}", file=file or sys.stderr)


class _Termination:
    """SIGTERM handled as SIGINT (a KeyboardInterrupt, so that a run writes its summary before it
    ends), remembering which signal came for the exit status (128 + its number)."""

    def __init__(self) -> None:
        self.signal = signal.SIGINT

    def __call__(self, signum: int, frame: object) -> None:  # noqa: ARG002
        self.signal = signal.Signals(signum)
        raise KeyboardInterrupt


#: what a command raises for bad input or a failing file: one line, exit status 2
EXPECTED_ERRORS = (ValueError, OSError, RuntimeError)
#: the exit status of a run ended by a signal is 128 + its number (130 for SIGINT, 143 for SIGTERM)
SIGNAL_EXIT_BASE = 128


def main(argv: list[str] | None = None) -> int:
    warnings.showwarning = show_warning
    argv = list(sys.argv[1:] if argv is None else argv)
    ros_args = argv[argv.index(ROS_ARGS) :] if ROS_ARGS in argv else []
    args = build_parser().parse_args(argv[: len(argv) - len(ros_args)])
    if ros_args and args.command not in ROS_COMMANDS:
        print(f"farlio {args.command}: error: {ROS_ARGS} is for {' and '.join(ROS_COMMANDS)}", file=sys.stderr)
        return 2
    args.ros_args = ros_args
    termination = _Termination()
    if args.command not in ROS_COMMANDS:  # the ROS 2 commands handle their own shutdown
        signal.signal(signal.SIGTERM, termination)
    try:
        return int(importlib.import_module(args._module).run(args) or 0)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return SIGNAL_EXIT_BASE + termination.signal
    except MemoryError as e:
        print(f"farlio {args.command}: error: out of memory ({e or 'an allocation failed'})", file=sys.stderr)
        return 2
    except EXPECTED_ERRORS as e:  # InputError is a ValueError
        print(f"farlio {args.command}: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
