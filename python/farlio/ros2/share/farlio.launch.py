"""Starts the farlio node with a parameter file: `ros2 launch farlio.launch.py` (this file's path).

Launch arguments: params_file (default: params.yaml beside this file; `farlio ros2 --print-params`
writes it), farlio (the executable, default `farlio` on PATH, e.g. .venv-ros/bin/farlio). farlio is
installed with pip, not as an ament package, so the node is started as a process; Ctrl-C stops it
cleanly (SIGINT). Topics, parameters and frames: docs/ros2.md.
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration

HERE = Path(__file__).resolve().parent


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "params_file", default_value=str(HERE / "params.yaml"), description="ROS parameter file of the node"
            ),
            DeclareLaunchArgument(
                "farlio", default_value="farlio", description="the farlio executable, e.g. .venv-ros/bin/farlio"
            ),
            ExecuteProcess(
                cmd=[
                    LaunchConfiguration("farlio"),
                    "ros2",
                    "--ros-args",
                    "--params-file",
                    LaunchConfiguration("params_file"),
                ],
                name="farlio",
                output="screen",
            ),
        ]
    )
