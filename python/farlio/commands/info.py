"""`farlio info`: what this build and machine offer."""

from __future__ import annotations

import argparse

import farlio


def add_arguments(parser: argparse.ArgumentParser) -> None:
    del parser  # no options


def run(args: argparse.Namespace) -> int:
    del args
    print(f"farlio {farlio.__version__}")
    print(f"CUDA backend compiled: {'yes' if farlio.cuda_compiled() else 'no'}")
    print(f"CUDA devices: {farlio.cuda_device_count()}")
    return 0
