"""farlio on ROS 2: the node (`farlio ros2`), the player (`farlio ros2-play`) and what they share.

Only `params` and `live` import without ROS; the rest needs the ROS 2 wheels of .venv-ros
(scripts/install_ros2.sh). docs/ros2.md describes topics, parameters and frames.
"""

from __future__ import annotations

import importlib.util

INSTALL_HINT = "rclpy is missing: the ROS 2 wheels live in .venv-ros (scripts/install_ros2.sh): use .venv-ros/bin/farlio"


def require_rclpy() -> None:
    """RuntimeError with the one-line install hint when rclpy cannot be imported."""
    if importlib.util.find_spec("rclpy") is None:
        raise RuntimeError(INSTALL_HINT)
    try:
        import rclpy  # noqa: F401
    except ImportError as e:
        raise RuntimeError(f"{INSTALL_HINT} (rclpy does not import: {e})") from None
