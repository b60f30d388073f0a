"""`farlio config`: every parameter with its default and meaning, as a YAML file to edit."""

from __future__ import annotations

import argparse
from pathlib import Path

import yaml

from farlio import _core


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=None, help="write the YAML here instead of printing it")


def _yaml_scalar(value) -> str:
    """A default as YAML reads it back: true/false, numbers (.inf for infinity), names."""
    return yaml.safe_dump(value, default_flow_style=True).removesuffix("\n...\n").strip()


def render() -> str:
    lines = [
        "# farlio parameters: dotted names, defaults, units in the names. Pass with --config FILE",
        "# or one at a time with --set name=value.",
    ]
    section = None
    for name, default, doc, valid in _core.Config.fields():
        head, _, leaf = name.rpartition(".")
        if head != section:
            section = head
            lines.append(f"{head}:" if head else "")
        indent = "  " if head else ""
        valid_text = f" [{valid}]" if valid else ""
        lines.append(f"{indent}{leaf or name}: {_yaml_scalar(default)}  # {doc}{valid_text}")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    text = render()
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text)
    else:
        print(text, end="")
    return 0
