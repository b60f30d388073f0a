"""The parameter set from Python: typed values, validation naming the field, the YAML round trip."""

from __future__ import annotations

import math
import re

import pytest
import yaml
from farlio import _core
from farlio.config import config_to_yaml, load_config


def test_values_keep_their_types():
    cfg = _core.Config()
    assert cfg.get("num_threads") == 0 and type(cfg.get("num_threads")) is int
    assert cfg.get("map.voxel_size_m") == 4.0 and type(cfg.get("map.voxel_size_m")) is float
    assert cfg.get("density.enabled") is True
    assert cfg.get("device") == "auto"
    d = cfg.to_dict()
    assert d["map.max_voxel_capacity"] == 1 << 20
    assert all(not isinstance(v, str) for k, v in d.items() if k != "device")


def test_set_takes_numbers_bools_and_text():
    cfg = _core.Config()
    cfg.set("map.voxel_size_m", 2)
    cfg.set("density.enabled", False)
    cfg.set("registration.max_iterations", "7")
    cfg.set("map.removal_radius_m", math.inf)
    assert cfg.get("map.voxel_size_m") == 2.0
    assert cfg.get("density.enabled") is False
    assert cfg.get("registration.max_iterations") == 7
    assert math.isinf(cfg.get("map.removal_radius_m"))
    assert repr(cfg) == (
        "Config(map.voxel_size_m=2, map.removal_radius_m=inf, density.enabled=false, registration.max_iterations=7)"
    )
    assert repr(_core.Config()) == "Config(defaults)"


@pytest.mark.parametrize(
    "name,value",
    [
        ("fusion.step_s", 0),
        ("map.voxel_size_m", -1.0),
        ("preprocess.min_range_m", math.nan),
        ("registration.max_iterations", 2.5),
        ("num_threads", -1),
    ],
)
def test_a_bad_value_is_an_error_naming_the_field_and_leaves_the_config(name, value):
    cfg = _core.Config()
    before = cfg.get(name)
    with pytest.raises(ValueError, match=name.replace(".", r"\.")):
        cfg.set(name, value)
    assert cfg.get(name) == before


def test_rules_between_fields_are_checked_when_loading(tmp_path):
    with pytest.raises(
        ValueError, match=r"preprocess.min_range_m \(300\) must be below preprocess.max_range_m \(200\)"
    ):
        load_config(overrides=["preprocess.min_range_m=300"])
    f = tmp_path / "bad.yaml"
    f.write_text("fusion:\n  reference_angles:\n    filter_taps: 4\n")
    with pytest.raises(ValueError, match=r"fusion\.reference_angles\.filter_taps must be odd"):
        load_config(f)


def test_the_written_yaml_reads_back_to_the_same_config(tmp_path):
    cfg = load_config(
        overrides=[
            "map.voxel_size_m=2.5",
            "fusion.enabled=false",
            "registration.damping=1e-7",
            "device=cpu",
            "registration.time_budget_factor=inf",
            "fusion.reference_angles.roll_std_rad=0.3",
        ]
    )
    f = tmp_path / "config.yaml"
    f.write_text(config_to_yaml(cfg))
    back = load_config(f)
    assert back == cfg
    assert back != _core.Config()


def test_sections_nest_three_levels_deep_or_take_dotted_keys(tmp_path):
    """A field of a sub-section (fusion.reference_angles.roll_std_rad) is read from nested mappings,
    from a dotted key at any level, or from the full dotted name."""
    expected = load_config(overrides=["fusion.step_s=0.02", "fusion.reference_angles.roll_std_rad=0.2"])
    assert expected.get("fusion.reference_angles.roll_std_rad") == 0.2
    texts = (
        "fusion:\n  step_s: 0.02\n  reference_angles:\n    roll_std_rad: 0.2\n",
        "fusion:\n  step_s: 0.02\n  reference_angles.roll_std_rad: 0.2\n",
        "fusion.step_s: 0.02\nfusion.reference_angles.roll_std_rad: 0.2\n",
    )
    for i, text in enumerate(texts):
        f = tmp_path / f"config{i}.yaml"
        f.write_text(text)
        assert load_config(f) == expected, text


@pytest.mark.parametrize(
    "old,new",
    [
        ("fusion.reference_roll_std_rad", "fusion.reference_angles.roll_std_rad"),
        ("fusion.estimate_imu_bias", "fusion.bias.estimate"),
        ("fusion.imu_gap_limit_s", "fusion.imu_gate.gap_limit_s"),
    ],
)
def test_a_renamed_field_is_an_error_that_names_its_new_name(tmp_path, old, new):
    """An old name, on the command line or in a YAML file, is an unknown field whose error names
    the field's new place."""
    expected = rf"unknown config field '{re.escape(old)}' \(renamed to {re.escape(new)}\)"
    with pytest.raises(ValueError, match=expected):
        load_config(overrides=[f"{old}=1"])
    section, leaf = old.split(".")
    f = tmp_path / "old.yaml"
    f.write_text(f"{section}:\n  {leaf}: 1\n")
    with pytest.raises(ValueError, match=expected):
        load_config(f)
    assert new in _core.Config().to_dict()


def test_fields_list_defaults_docs_and_ranges():
    fields = _core.Config.fields()
    names = [f[0] for f in fields]
    assert len(names) == len(set(names)) == len(_core.Config().to_dict())
    by_name = {f[0]: f for f in fields}
    assert by_name["fusion.step_s"][1:] == (0.01, by_name["fusion.step_s"][2], "in [1e-04, 1]")
    assert all(doc for _, _, doc, _ in fields)


@pytest.mark.parametrize("everything", [False, True])
def test_farlio_config_prints_the_essential_fields_or_all_and_reads_back(tmp_path, everything):
    """`farlio config` writes the essential fields (each a real field, each once), `--all` every field;
    either file loads back to the defaults, the essential one because a field left out keeps its
    default."""
    from farlio.cli import main
    from farlio.commands.config import ESSENTIAL_FIELDS

    names = [f[0] for f in _core.Config.fields()]
    assert set(ESSENTIAL_FIELDS) <= set(names) and len(set(ESSENTIAL_FIELDS)) == len(ESSENTIAL_FIELDS)
    out = tmp_path / "config.yaml"
    assert main(["config", "--out", str(out), *(["--all"] if everything else [])]) == 0

    def leaves(node: dict, prefix: str = ""):
        for key, value in node.items():
            yield from leaves(value, f"{prefix}{key}.") if isinstance(value, dict) else [f"{prefix}{key}"]

    written = list(leaves(yaml.safe_load(out.read_text())))
    assert len(written) == len(set(written))
    assert set(written) == (set(names) if everything else set(ESSENTIAL_FIELDS))
    assert ("fusion.reference_angles.roll_std_rad" in written) == everything
    assert load_config(out) == _core.Config()
