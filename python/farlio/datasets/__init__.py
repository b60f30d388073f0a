"""Dataloaders: every recording format `farlio run` reads, detected from the path.

A dataset gives scans (farlio.Scan with stamps and per-point times), and where it has them the
IMU samples, the LiDAR-IMU extrinsic and ground truth. See docs/datasets.md.
"""

from __future__ import annotations

from pathlib import Path

from .base import Dataset, LoadOptions
from .folders import KittiOdometry, PointCloudFolder, SequenceFolder
from .kitti_raw import KittiRaw
from .mulran import MulRan
from .ouster import OusterRecording
from .pointcloud2 import TimeOptions
from .rosbag import RosBag

#: detection order: the first whose `matches` accepts the path wins
FORMATS = {
    "sequence": SequenceFolder,
    "kitti": KittiOdometry,
    "kitti-raw": KittiRaw,
    "mulran": MulRan,
    "ouster": OusterRecording,
    "rosbag": RosBag,
    "folder": PointCloudFolder,
}
FORMAT_HELP = (
    "sequence folder (lidar/), KITTI odometry (velodyne/ + times.txt), KITTI raw drive "
    "(velodyne_points/ + oxts/), MulRan (sensor_data/Ouster/), Ouster .pcap (+ .json) or a bag of "
    "Ouster packets, ROS 1 .bag or ROS 2 bag (folder with metadata.yaml, .db3, .mcap), "
    "a folder of .pcd/.ply/.bin files"
)


def detect_format(path: Path) -> str:
    """The format name of `path`, by its layout."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file or folder")
    for name, cls in FORMATS.items():
        if cls.matches(path):
            return name
    raise ValueError(
        f"{path}: cannot tell its format; expected one of: {FORMAT_HELP}; or pass --format with "
        f"one of: {', '.join(FORMATS)}"
    )


def open_dataset(path: Path, fmt: str = "auto", options: LoadOptions | None = None) -> Dataset:
    """Opens a recording; `fmt` is a name of FORMATS or 'auto'."""
    name = detect_format(path) if fmt == "auto" else fmt
    if name not in FORMATS:
        raise ValueError(f"unknown format '{fmt}'; expected auto or one of: {', '.join(FORMATS)}")
    if not Path(path).exists():
        raise FileNotFoundError(f"{path}: no such file or folder")
    return FORMATS[name](Path(path), options or LoadOptions())


__all__ = ["Dataset", "FORMATS", "LoadOptions", "TimeOptions", "detect_format", "open_dataset"]
