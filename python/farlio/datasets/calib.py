"""Extrinsics for recordings that do not carry them: a calibration YAML file, and helpers to turn
4x4 matrices and translation + quaternion into farlio.SE3.

The calibration file (`--calib`) is the sequence folder's calib.yaml (`T_imu_lidar`: 4x4 row-major,
maps LiDAR points into the IMU/body frame; `gravity`), where for several LiDARs `T_imu_lidar` may
be a mapping from topic (or frame id) to 4x4 matrix.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import yaml

import farlio

#: how far from a rigid transform a calibration matrix may be (rotation orthonormality, last row)
RIGID_TOLERANCE = 1e-4


def se3_from_matrix(m: Any, where: str) -> farlio.SE3:
    a = np.asarray(m, dtype=np.float64)
    if a.shape != (4, 4):
        raise ValueError(f"{where}: expected a 4x4 matrix, got shape {a.shape}")
    r = a[:3, :3]
    if (np.abs(r @ r.T - np.eye(3)).max() > RIGID_TOLERANCE or
            np.abs(a[3] - [0, 0, 0, 1]).max() > RIGID_TOLERANCE or np.linalg.det(r) < 0):
        raise ValueError(f"{where}: not a rigid transform (rotation not orthonormal or last row not 0 0 0 1)")
    return farlio.SE3.from_matrix(a)


def se3_from_quaternion(t: Any, q_xyzw: Any) -> farlio.SE3:
    """The transform with translation t and rotation quaternion (x, y, z, w)."""
    x, y, z, w = (float(v) for v in q_xyzw)
    n = np.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = [float(v) for v in t]
    return farlio.SE3.from_matrix(m)


class CalibFile:
    """A calibration YAML: `T_imu_lidar` (one 4x4, or {topic or frame: 4x4}) and optional `gravity`."""

    def __init__(self, path: Path):
        self.path = Path(path)
        try:
            doc = yaml.safe_load(self.path.read_text())
        except yaml.YAMLError as e:
            raise ValueError(f"{self.path}: not YAML: {e}") from None
        if not isinstance(doc, dict) or "T_imu_lidar" not in doc:
            raise ValueError(f"{self.path}: expected a key 'T_imu_lidar' (4x4 row-major, or a mapping from "
                             f"LiDAR topic/frame to 4x4)")
        value = doc["T_imu_lidar"]
        if isinstance(value, dict):
            self._by_name = {str(k): se3_from_matrix(v, f"{self.path}: T_imu_lidar[{k}]") for k, v in value.items()}
            self._single = None
        else:
            self._by_name = {}
            self._single = se3_from_matrix(value, f"{self.path}: T_imu_lidar")
        self.gravity_m_s2 = float(doc["gravity"]) if "gravity" in doc else None

    def T_imu_lidar(self, *names: str) -> farlio.SE3:
        """The extrinsic of the LiDAR known by any of `names` (topic, frame id)."""
        if self._single is not None:
            return self._single
        for n in names:
            if n in self._by_name:
                return self._by_name[n]
        raise ValueError(f"{self.path}: T_imu_lidar has no entry for {' or '.join(repr(n) for n in names)} "
                         f"(entries: {', '.join(self._by_name)})")
