"""`farlio config`: the parameters with their defaults and meaning, as a YAML file to edit: the
essential ones (what a user sets for a sensor, a platform or a computer) by default, every one with
`--all`. Every field keeps its default in any file that leaves it out."""

from __future__ import annotations

import argparse
from pathlib import Path

import yaml

from farlio import _core

#: the fields a user sets for a sensor, a platform or a computer; the others are the method's own
#: (docs/odometry.md, docs/fusion.md) and serve every sensor and dataset at their defaults
ESSENTIAL_FIELDS = (
    "device",
    "num_threads",
    "preprocess.min_range_m",
    "preprocess.max_range_m",
    "map.voxel_size_m",
    "map.max_points_per_voxel",
    "registration.time_budget_factor",
    "fusion.enabled",
    "fusion.gyro_input_std_rad_s",
    "fusion.accel_input_std_m_s2",
    "localization.min_inlier_fraction",
    "loop.keyframe_distance_m",
    "loop.search_radius_m",
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, default=None, help="write the YAML here instead of printing it")
    parser.add_argument(
        "--all",
        action="store_true",
        help=f"every parameter ({len(_core.Config.fields())}) instead of the {len(ESSENTIAL_FIELDS)} essential ones",
    )


def _yaml_scalar(value) -> str:
    """A default as YAML reads it back: true/false, numbers (.inf for infinity), names."""
    return yaml.safe_dump(value, default_flow_style=True).removesuffix("\n...\n").strip()


def render(everything: bool = True) -> str:
    """The YAML of every field (everything) or of ESSENTIAL_FIELDS, in the config's order."""
    fields = _core.Config.fields()
    which = "every parameter" if everything else f"the essential parameters ({len(fields)} with --all)"
    lines = [
        f"# farlio: {which}: dotted names, defaults, units in the names. Pass with --config FILE",
        "# or one at a time with --set name=value; a field left out keeps its default.",
    ]
    opened: list[str] = []  # the sections (outermost first) the previous field was written in
    for name, default, doc, valid in fields:
        if not everything and name not in ESSENTIAL_FIELDS:
            continue
        *sections, leaf = name.split(".")
        shared = 0
        while shared < min(len(opened), len(sections)) and opened[shared] == sections[shared]:
            shared += 1
        if not sections and opened:
            lines.append("")  # the top-level fields after the last section
        lines.extend(f"{'  ' * depth}{sections[depth]}:" for depth in range(shared, len(sections)))
        opened = sections
        valid_text = f" [{valid}]" if valid else ""
        lines.append(f"{'  ' * len(sections)}{leaf}: {_yaml_scalar(default)}  # {doc}{valid_text}")
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    text = render(args.all)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text)
    else:
        print(text, end="")
    return 0
