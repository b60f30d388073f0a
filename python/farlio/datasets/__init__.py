"""Dataloaders: every recording format `farlio run` reads, detected from the path.

A dataset gives scans (farlio.Scan with stamps and per-point times), and where it has them the
IMU samples, the LiDAR-IMU extrinsic and ground truth. See docs/datasets.md.
"""
from __future__ import annotations

from pathlib import Path

from .base import Dataset
from .folders import KittiOdometry, PointCloudFolder, SequenceFolder

FORMATS = {
    "sequence": SequenceFolder,
    "kitti": KittiOdometry,
    "folder": PointCloudFolder,
}


def detect_format(path: Path) -> str:
    """The format name of `path`, by its layout."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file or folder")
    for name, cls in FORMATS.items():
        if cls.matches(path):
            return name
    raise ValueError(
        f"{path}: cannot tell its format (expected a sequence folder with lidar/, a KITTI sequence with "
        f"velodyne/, or a folder of .pcd/.ply/.bin files); pass --format with one of: {', '.join(FORMATS)}"
    )


def open_dataset(path: Path, fmt: str = "auto") -> Dataset:
    """Opens a recording; `fmt` is a name of FORMATS or 'auto'."""
    name = detect_format(path) if fmt == "auto" else fmt
    if name not in FORMATS:
        raise ValueError(f"unknown format '{fmt}'; expected auto or one of: {', '.join(FORMATS)}")
    return FORMATS[name](Path(path))


__all__ = ["Dataset", "FORMATS", "detect_format", "open_dataset"]
