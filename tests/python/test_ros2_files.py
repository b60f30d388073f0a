"""The files shipped for ROS 2 users (python/farlio/ros2/share): the default parameter file is the
one the node generates (every parameter, valid YAML), and the launch file builds the command that
starts the node with it. launch_ros and launch are not installable here: the launch file runs
against stand-ins of the three `launch` classes it uses."""

from __future__ import annotations

import runpy
import sys
import types
from pathlib import Path

import farlio
import yaml
from farlio.ros2.params import NODE_NAME, default_params_yaml, node_param_docs

SHARE = Path(farlio.__file__).parent / "ros2" / "share"


def test_shipped_parameter_file_is_the_generated_one_and_names_every_parameter():
    text = (SHARE / "params.yaml").read_text()
    assert text == default_params_yaml(), (
        "regenerate: farlio ros2 --print-params > python/farlio/ros2/share/params.yaml"
    )
    params = yaml.safe_load(text)[NODE_NAME]["ros__parameters"]
    names = [n for n, *_ in node_param_docs()] + [n for n, *_ in farlio.Config.fields()]
    assert sorted(params) == sorted(names)
    assert params["lidar_topics"] == ["/points"] and params["map.voxel_size_m"] == farlio.Config().get(
        "map.voxel_size_m"
    )


class _Recorded:
    """Stands in for a launch class: keeps its arguments."""

    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


def test_launch_file_starts_the_node_with_the_parameter_file(monkeypatch):
    classes = {
        "launch": ["LaunchDescription"],
        "launch.actions": ["DeclareLaunchArgument", "ExecuteProcess"],
        "launch.substitutions": ["LaunchConfiguration"],
    }
    for module, names in classes.items():
        stub = types.ModuleType(module)
        for name in names:
            setattr(stub, name, type(name, (_Recorded,), {}))
        monkeypatch.setitem(sys.modules, module, stub)
    description = runpy.run_path(str(SHARE / "farlio.launch.py"))["generate_launch_description"]()
    actions = description.args[0]
    declared = {a.args[0]: a.kwargs["default_value"] for a in actions if type(a).__name__ == "DeclareLaunchArgument"}
    assert (
        Path(declared["params_file"]) == (SHARE / "params.yaml").resolve() and Path(declared["params_file"]).is_file()
    )
    (process,) = [a for a in actions if type(a).__name__ == "ExecuteProcess"]
    cmd = [c.args[0] if type(c).__name__ == "LaunchConfiguration" else c for c in process.kwargs["cmd"]]
    assert cmd == ["farlio", "ros2", "--ros-args", "--params-file", "params_file"]
    assert all(name in declared for name in ("farlio", "params_file"))


def test_docs_name_every_node_parameter():
    docs = (Path(__file__).parents[2] / "docs" / "ros2.md").read_text()
    missing = [n for n, *_ in node_param_docs() if f"| `{n}` |" not in docs]
    assert not missing, f"docs/ros2.md lacks {missing}"
