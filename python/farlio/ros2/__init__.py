"""farlio on ROS 2: the node (`farlio ros2`), the player (`farlio ros2-play`) and what they share.

Only `params` and `live` import without ROS; the rest needs the ROS 2 wheels of .venv-ros
(scripts/install_ros2.sh). docs/ros2.md describes topics, parameters and frames.
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

INSTALL_HINT = (
    "rclpy is missing: the ROS 2 wheels live in .venv-ros (scripts/install_ros2.sh): use .venv-ros/bin/farlio"
)


def require_rclpy() -> None:
    """RuntimeError with the one-line install hint when rclpy cannot be imported."""
    if importlib.util.find_spec("rclpy") is None:
        raise RuntimeError(INSTALL_HINT)
    try:
        import rclpy  # noqa: F401
    except ImportError as e:
        raise RuntimeError(f"{INSTALL_HINT} (rclpy does not import: {e})") from None


#: Fast DDS profile for large clouds on one machine (shared memory with a 16 MiB segment)
FASTDDS_PROFILE = Path(__file__).with_name("fastdds_large_data.xml")
#: values of --transport
TRANSPORTS = ("large-data", "ros-default")
_PROFILE_VARIABLES = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE")
_FASTDDS_RMW = ("", "rmw_fastrtps_cpp")


def choose_transport(transport: str) -> str:
    """Before rclpy.init: with 'large-data', Fast DDS (the default RMW) gets FASTDDS_PROFILE unless
    a profile file is already set in the environment. Returns what is used, for the log."""
    if transport not in TRANSPORTS:
        raise ValueError(f"--transport {transport}: expected one of {', '.join(TRANSPORTS)}")
    given = next((os.environ[v] for v in _PROFILE_VARIABLES if os.environ.get(v)), None)
    if given:
        return f"Fast DDS profile {given} (from the environment)"
    if transport == "ros-default" or os.environ.get("RMW_IMPLEMENTATION", "") not in _FASTDDS_RMW:
        return "the RMW's default transports"
    os.environ[_PROFILE_VARIABLES[0]] = str(FASTDDS_PROFILE)
    return f"Fast DDS profile {FASTDDS_PROFILE} (shared memory for large clouds)"


def add_transport_argument(parser) -> None:
    parser.add_argument(
        "--transport",
        default="large-data",
        choices=TRANSPORTS,
        help="large-data: Fast DDS with shared memory big enough for whole clouds (the shipped profile "
        "fastdds_large_data.xml; a profile file set in the environment wins); ros-default: the RMW's own "
        "settings (docs/ros2.md)",
    )
