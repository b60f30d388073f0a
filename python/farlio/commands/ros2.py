"""`farlio ros2`: the ROS 2 node (docs/ros2.md); parameters are ROS parameters:
`farlio ros2 --ros-args --params-file params.yaml -p lidar_topics:=[/points]`."""

from __future__ import annotations

import argparse

from farlio.ros2 import add_transport_argument, choose_transport, require_rclpy
from farlio.ros2.params import default_params_yaml


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.epilog = (
        "ROS arguments follow --ros-args: --params-file FILE, -p name:=value, -r from:=to. Every "
        "parameter with its default and meaning: farlio ros2 --print-params"
    )
    parser.add_argument("--print-params", action="store_true", help="print the default parameter file (YAML) and exit")
    add_transport_argument(parser)


def run(args: argparse.Namespace) -> int:
    if args.print_params:
        print(default_params_yaml(), end="")
        return 0
    require_rclpy()
    transport = choose_transport(args.transport)
    from farlio.ros2.node import run as run_node

    return run_node(args.ros_args, transport)
