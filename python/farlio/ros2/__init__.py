"""farlio on ROS 2: the node (`farlio ros2`), the player (`farlio ros2-play`) and what they share.

Only `params` and `live` import without ROS; the rest needs the ROS 2 wheels of .venv-ros
(scripts/install_ros2.sh). docs/ros2.md describes topics, parameters and frames.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
from pathlib import Path

INSTALL_HINT = (
    "rclpy is missing: the ROS 2 wheels live in .venv-ros (scripts/install_ros2.sh): use .venv-ros/bin/farlio"
)
#: how long `farlio ros2-play` waits for a subscriber on every topic by default: Fast DDS announces
#: a participant a few times at its start and then every 3 s, so a missed first announcement (a
#: loaded machine) costs one period or more
WAIT_SUBSCRIBERS_S = 10.0


def require_rclpy() -> None:
    """RuntimeError with the one-line install hint when rclpy cannot be imported."""
    if importlib.util.find_spec("rclpy") is None:
        raise RuntimeError(INSTALL_HINT)
    try:
        import rclpy  # noqa: F401
    except ImportError as e:
        raise RuntimeError(f"{INSTALL_HINT} (rclpy does not import: {e})") from None


#: glibc's mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: buffers up to this size come from the heap rather than from fresh mmap'd pages (glibc's maximum)
HEAP_BUFFER_MAX_BYTES = 32 << 20
#: freed memory the process keeps for its next buffers instead of giving it back to the OS
FREED_MEMORY_KEPT_BYTES = 64 << 20


def retain_freed_memory() -> bool:
    """Makes glibc keep freed memory for the next cloud. By default it gives freed memory at the top
    of the heap back to the OS and serves buffers over its (adaptive) threshold from fresh mmap'd
    pages, so every cloud's few MB of buffers fault their pages in again: ~570 page faults and
    ~1.5 ms of CPU for a 117k-point scan on the machine of docs/ros2.md. Returns whether it applied
    (False without glibc)."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, HEAP_BUFFER_MAX_BYTES)) and bool(
        mallopt(_M_TRIM_THRESHOLD, FREED_MEMORY_KEPT_BYTES)
    )


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
