"""Extrinsics for recordings that do not carry them: a calibration YAML file, and helpers to turn
4x4 matrices and translation + quaternion into farlio.SE3.

The calibration file (`--calib`) is the sequence folder's calib.yaml (`T_imu_lidar`: 4x4 row-major,
maps LiDAR points into the IMU/body frame; `gravity`), where for several LiDARs `T_imu_lidar` may
be a mapping from topic (or frame id) to 4x4 matrix. It is read, and matrices are checked to be
rigid, by the C++ reader (farlio._core.io, docs/io.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import farlio
from farlio import _core

MATRIX_SHAPE = (4, 4)


def se3_from_matrix(m: Any, where: str) -> farlio.SE3:
    """The rigid transform of a 4x4 matrix; ValueError naming `where` if it is not one."""
    a = np.asarray(m, dtype=np.float64)
    if a.shape != MATRIX_SHAPE:
        raise ValueError(f"{where}: expected a 4x4 matrix, got shape {a.shape}")
    return _core.io.rigid_transform_from_matrix(a, where)


def se3_from_quaternion(t: Any, q_xyzw: Any) -> farlio.SE3:
    """The transform with translation t and rotation quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in q_xyzw)
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = [float(v) for v in t]
    return farlio.SE3.from_matrix(m)


class CalibFile:
    """A calibration YAML: `T_imu_lidar` (one 4x4, or {topic or frame: 4x4}) and optional `gravity`."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self._calib = _core.io.read_calibration(self.path)

    @property
    def gravity_m_s2(self) -> float | None:
        """The file's gravity; None when it does not state one."""
        return self._calib.gravity_m_s2

    def T_imu_lidar(self, *names: str) -> farlio.SE3:
        """The extrinsic of the LiDAR known by any of `names` (topic, frame id)."""
        return self._calib.lidar_extrinsic(list(names))
