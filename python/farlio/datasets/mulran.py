"""MulRan sequences: sensor_data/Ouster/<stamp_ns>.bin (float32 x y z intensity, no per-point
time), sensor_data/data_stamp.csv (stamp,sensor per line) and global_pose.csv (stamp then a 3x4
row-major pose of the vehicle base per line), optionally sensor_data/xsens_imu.csv.

Scan end stamps are the file names. The ground truth (global_pose.csv) is written as a TUM file
into a cache folder beside nothing of the recording (the system's temporary folder). The Xsens
IMU is used only with --calib (its extrinsic to the Ouster is not in the recording).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import farlio

from .base import LoadOptions, write_temporary_tum
from .calib import CalibFile
from .folders import _FilesWithStamps

OUSTER_DIR = Path("sensor_data") / "Ouster"
DATA_STAMP = Path("sensor_data") / "data_stamp.csv"
XSENS_IMU = Path("sensor_data") / "xsens_imu.csv"
GLOBAL_POSE = "global_pose.csv"
OUSTER_SENSOR = "ouster"
POSE_COLUMNS = 13  # stamp + 3x4
#: xsens_imu.csv: stamp, quaternion (4), euler (3), gyro (3), accel (3), magnetometer (3)
XSENS_GYRO_COLUMNS = slice(8, 11)
XSENS_ACCEL_COLUMNS = slice(11, 14)
XSENS_MIN_COLUMNS = 14


def read_stamped_csv(path: Path, min_columns: int) -> tuple[list[int], np.ndarray]:
    """Rows 'stamp_ns, v1, v2, ...': integer stamps (exact, beyond float precision) and the values."""
    stamps, rows = [], []
    for k, line in enumerate(path.read_text().splitlines()):
        parts = line.split(",")
        if not line.strip() or not parts[0].strip().isdigit():
            continue  # blank or header line
        if len(parts) < min_columns:
            raise ValueError(f"{path}:{k + 1}: {len(parts)} columns; expected at least {min_columns}")
        try:
            rows.append([float(v) for v in parts[1:min_columns]])
        except ValueError:
            raise ValueError(f"{path}:{k + 1}: a value is not a number") from None
        stamps.append(int(parts[0]))
    return stamps, np.array(rows, dtype=np.float64).reshape(len(rows), min_columns - 1)


class MulRan(_FilesWithStamps):
    """A MulRan sequence folder (the one holding sensor_data/ and global_pose.csv)."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        return (Path(path) / OUSTER_DIR).is_dir()

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self.options = options or LoadOptions()
        self._warnings = [f"{self.path}: MulRan scans have no per-point time: they are not undistorted"]
        files = {p.stem: p for p in (self.path / OUSTER_DIR).glob("*.bin")}
        bad = [s for s in files if not s.isdigit()]
        if bad:
            raise ValueError(f"{self.path / OUSTER_DIR}: file names must be stamps in ns, found {bad[0]}.bin")
        stamps = sorted(int(s) for s in files)
        if (self.path / DATA_STAMP).exists():
            listed = self._listed_stamps()
            missing = [s for s in listed if str(s) not in files]
            if missing:
                self._warnings.append(
                    f"{self.path / DATA_STAMP}: {len(missing)} Ouster stamps without a file in "
                    f"{OUSTER_DIR} (first {missing[0]}); those scans are left out"
                )
            stamps = [s for s in listed if str(s) in files]
        if not stamps:
            raise ValueError(f"{self.path / OUSTER_DIR}: no <stamp_ns>.bin scans")
        self._stamps = stamps
        self._files = [files[str(s)] for s in stamps]
        self._calib = CalibFile(self.options.calib) if self.options.calib is not None else None
        self._gt: Path | None = None

    def _listed_stamps(self) -> list[int]:
        out = []
        for k, line in enumerate((self.path / DATA_STAMP).read_text().splitlines()):
            parts = [p.strip() for p in line.split(",")]
            if len(parts) != 2 or not parts[0].isdigit():
                raise ValueError(f"{self.path / DATA_STAMP}:{k + 1}: expected 'stamp_ns,sensor', got '{line}'")
            if parts[1] == OUSTER_SENSOR:
                out.append(int(parts[0]))
        return out

    def imu(self) -> list[farlio.ImuSample]:
        path = self.path / XSENS_IMU
        if not path.exists():
            return []
        if self._calib is None:
            if not any("xsens" in w for w in self._warnings):
                self._warnings.append(
                    f"{path} is not used without --calib (the Xsens-Ouster extrinsic): LiDAR-only odometry"
                )
            return []
        stamps, table = read_stamped_csv(path, XSENS_MIN_COLUMNS)
        gyro, accel = (
            table[:, XSENS_GYRO_COLUMNS.start - 1 : XSENS_GYRO_COLUMNS.stop - 1],
            table[:, XSENS_ACCEL_COLUMNS.start - 1 : XSENS_ACCEL_COLUMNS.stop - 1],
        )
        return [farlio.ImuSample(s, g, a) for s, g, a in zip(stamps, gyro, accel)]

    def T_imu_lidar(self) -> farlio.SE3:
        return self._calib.T_imu_lidar("ouster") if self._calib is not None else farlio.SE3()

    def groundtruth(self) -> Path | None:
        src = self.path / GLOBAL_POSE
        if not src.exists():
            return None
        if self._gt is None:
            stamps, table = read_stamped_csv(src, POSE_COLUMNS)
            traj = farlio.Trajectory()
            for stamp, r in zip(stamps, table):
                m = np.eye(4)
                m[:3, :] = r.reshape(3, 4)
                traj.push_back(stamp, farlio.SE3.from_matrix(m))
            self._gt = write_temporary_tum(traj, "farlio-mulran-")
        return self._gt

    def warnings(self) -> list[str]:
        self.imu()
        return list(self._warnings)
