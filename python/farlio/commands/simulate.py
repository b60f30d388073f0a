"""`farlio simulate`: not yet available in this build."""
from __future__ import annotations

import argparse


def add_arguments(parser: argparse.ArgumentParser) -> None:
    del parser


def run(args: argparse.Namespace) -> int:
    del args
    raise RuntimeError("this command is not implemented yet")
