"""The parameter set from Python: defaults, YAML files and `key=value` overrides.

Field names are the dotted names of the C++ Config (e.g. ``map.voxel_size_m``,
``fusion.reference_angles.roll_std_rad``); a YAML file may nest them at any level
(``fusion: {reference_angles: {roll_std_rad: 0.2}}``) or write them dotted
(``fusion: {reference_angles.roll_std_rad: 0.2}``). Unknown names are errors that name the field
(and its new name when it moved into a sub-section).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

import yaml

from ._core import Config


def _flatten(d: dict, prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in d.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_flatten(v, name + "."))
        else:
            out[name] = v
    return out


def _yaml_error_place(path: Path, error: yaml.YAMLError) -> str:
    """file:line of a YAML error (the file alone when the parser gives no line)."""
    mark = getattr(error, "problem_mark", None)
    return f"{path}:{mark.line + 1}" if mark is not None else str(path)


def load_config(yaml_path: Path | None = None, overrides: Iterable[str] = ()) -> Config:
    """Defaults, then the YAML file, then `key=value` overrides (later wins)."""
    cfg = Config()
    if yaml_path is not None:
        try:
            data = yaml.safe_load(Path(yaml_path).read_text()) or {}
        except yaml.YAMLError as e:
            problem = getattr(e, "problem", None) or e
            raise ValueError(f"{_yaml_error_place(yaml_path, e)}: not valid YAML ({problem})") from None
        if not isinstance(data, dict):
            raise ValueError(f"{yaml_path}: expected a mapping of config fields")
        for name, value in _flatten(data).items():
            try:
                cfg.set(name, value)
            except ValueError as e:
                raise ValueError(f"{yaml_path}: {e}") from None
    for item in overrides:
        if "=" not in item:
            raise ValueError(f"--set expects key=value, got '{item}'")
        name, value = item.split("=", 1)
        cfg.set(name.strip(), value.strip())
    cfg.validate()  # the rules between fields (each value was checked as it was set)
    return cfg


def config_to_yaml(cfg: Config) -> str:
    """The full effective config as nested YAML (every field, defaults included)."""
    nested: dict[str, Any] = {}
    for name, value in cfg.to_dict().items():
        node = nested
        *parents, leaf = name.split(".")
        for p in parents:
            node = node.setdefault(p, {})
        node[leaf] = value
    return yaml.safe_dump(nested, sort_keys=False)
