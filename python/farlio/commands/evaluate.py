"""`farlio eval`: compare a trajectory with ground truth (implementation in farlio.evaluation)."""

from __future__ import annotations

import argparse

from farlio.evaluation import add_eval_arguments, run_eval


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_eval_arguments(parser)


def run(args: argparse.Namespace) -> int:
    return run_eval(args)
