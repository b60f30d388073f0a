"""KITTI raw drives (`<date>_drive_<n>_sync` or `_extract`): velodyne_points/data/*.bin with their
timestamps, the OXTS IMU (oxts/data/*.txt + oxts/timestamps.txt) and the IMU-to-Velodyne
calibration (calib_imu_to_velo.txt in the drive folder or its parent, the date folder).

Scans have no per-point time (the .bin files do not carry it), so they are not undistorted. Scan
start/end come from velodyne_points/timestamps_start.txt and timestamps_end.txt when present,
else timestamps.txt is taken as the scan end. The IMU is the OXTS: acceleration ax, ay, az (m/s^2,
gravity included) and angular rate wx, wy, wz (rad/s) in the OXTS frame (x forward, y left, z up).
The OXTS poses (latitude, longitude, altitude, roll, pitch, yaw) become the ground truth of the
body (OXTS) frame, as in the KITTI devkit: Mercator projection with the first latitude's scale,
rotation Rz(yaw) Ry(pitch) Rx(roll), relative to the first pose (a TUM file in a temporary folder).
"""

from __future__ import annotations

import math
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

import farlio
from farlio._core import NS_PER_S

from .base import LoadOptions, write_temporary_tum
from .calib import CalibFile, se3_from_matrix
from .folders import DEFAULT_PERIOD_NS, _FilesWithStamps

CALIB_FILE = "calib_imu_to_velo.txt"
#: columns of an OXTS line (KITTI devkit dataformat.txt)
OXTS_ACCEL_COLUMNS = slice(11, 14)  # ax ay az
OXTS_GYRO_COLUMNS = slice(17, 20)  # wx wy wz
OXTS_COLUMNS = 30
OXTS_POSE_COLUMNS = slice(0, 6)  # lat lon alt roll pitch yaw
#: the Earth radius of the KITTI devkit's Mercator projection
EARTH_RADIUS_M = 6378137.0


def parse_kitti_stamp(text: str, where: str) -> int:
    """'2011-09-26 13:02:25.964389445' (UTC) -> ns since the epoch (nanosecond digits kept)."""
    try:
        whole, _, frac = text.strip().partition(".")
        t = datetime.strptime(whole, "%Y-%m-%d %H:%M:%S").replace(tzinfo=timezone.utc)
        return int(t.timestamp()) * NS_PER_S + int((frac + "000000000")[:9])
    except ValueError:
        raise ValueError(
            f"{where}: '{text.strip()}' is not a KITTI timestamp (YYYY-MM-DD HH:MM:SS.fffffffff)"
        ) from None


def read_stamps(path: Path) -> list[int]:
    return [
        parse_kitti_stamp(line, f"{path}:{k + 1}")
        for k, line in enumerate(path.read_text().splitlines())
        if line.strip()
    ]


def oxts_pose(lat_lon_alt_rpy: np.ndarray, scale: float) -> np.ndarray:
    """The OXTS frame's 4x4 pose in the local Mercator frame (KITTI devkit convertOxtsToPose)."""
    lat, lon, alt, roll, pitch, yaw = (float(v) for v in lat_lon_alt_rpy)
    t = [
        scale * math.radians(lon) * EARTH_RADIUS_M,
        scale * EARTH_RADIUS_M * math.log(math.tan(math.radians(90.0 + lat) / 2.0)),
        alt,
    ]
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    m[:3, 3] = t
    return m


def read_imu_to_velo(path: Path) -> farlio.SE3:
    """calib_imu_to_velo.txt: 'R: 9 numbers' and 'T: 3 numbers', mapping IMU points into the Velodyne frame."""
    values = {}
    for line in path.read_text().splitlines():
        key, _, rest = line.partition(":")
        if key.strip() in ("R", "T"):
            values[key.strip()] = [float(v) for v in rest.split()]
    if len(values.get("R", [])) != 9 or len(values.get("T", [])) != 3:
        raise ValueError(f"{path}: expected lines 'R: <9 numbers>' and 'T: <3 numbers>'")
    m = np.eye(4)
    m[:3, :3] = np.reshape(values["R"], (3, 3))
    m[:3, 3] = values["T"]
    return se3_from_matrix(m, str(path))


class KittiRaw(_FilesWithStamps):
    """A KITTI raw drive folder with velodyne_points/ and oxts/."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        return (Path(path) / "velodyne_points" / "data").is_dir()

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self.options = options or LoadOptions()
        self._warnings: list[str] = []
        velo = self.path / "velodyne_points"
        self._files = sorted(p for p in (velo / "data").iterdir() if p.suffix == ".bin")
        if not self._files:
            raise ValueError(f"{velo / 'data'}: no .bin scans")
        start_file, end_file = velo / "timestamps_start.txt", velo / "timestamps_end.txt"
        if end_file.exists():
            self._stamps = self._checked(read_stamps(end_file), end_file)
            self._starts = self._checked(read_stamps(start_file), start_file) if start_file.exists() else None
        elif (velo / "timestamps.txt").exists():
            self._stamps = self._checked(read_stamps(velo / "timestamps.txt"), velo / "timestamps.txt")
            self._starts = None
        else:
            self._stamps = [(i + 1) * DEFAULT_PERIOD_NS for i in range(len(self._files))]
            self._starts = None
            self._warnings.append(f"{velo}: no timestamps*.txt: scans assumed {DEFAULT_PERIOD_NS / 1e6:g} ms apart")
        self._warnings.append(f"{self.path}: KITTI scans have no per-point time: they are not undistorted")
        self._oxts_stamps: list[int] = []
        self._oxts_poses: list[np.ndarray] = []
        self._gt: Path | None = None
        self._imu = self._read_oxts()
        self._T_imu_lidar = self._read_extrinsic()

    def _checked(self, stamps: list[int], where: Path) -> list[int]:
        if len(stamps) != len(self._files):
            raise ValueError(
                f"{where}: {len(stamps)} stamps for {len(self._files)} scans in "
                f"{self.path / 'velodyne_points' / 'data'}"
            )
        return stamps

    def _read_oxts(self) -> list[farlio.ImuSample]:
        oxts = self.path / "oxts"
        if not (oxts / "timestamps.txt").exists():
            self._warnings.append(f"{self.path}: no oxts/timestamps.txt: LiDAR-only odometry")
            return []
        stamps = read_stamps(oxts / "timestamps.txt")
        files = sorted((oxts / "data").glob("*.txt"))
        if len(files) != len(stamps):
            raise ValueError(
                f"{oxts / 'timestamps.txt'}: {len(stamps)} stamps for {len(files)} files in {oxts / 'data'}"
            )
        samples = []
        self._oxts_stamps = stamps
        for stamp, f in zip(stamps, files):
            v = f.read_text().split()
            if len(v) != OXTS_COLUMNS:
                raise ValueError(f"{f}: {len(v)} values; an OXTS line has {OXTS_COLUMNS}")
            try:
                a = np.array(v[OXTS_ACCEL_COLUMNS], dtype=np.float64)
                w = np.array(v[OXTS_GYRO_COLUMNS], dtype=np.float64)
                self._oxts_poses.append(np.array(v[OXTS_POSE_COLUMNS], dtype=np.float64))
            except ValueError:
                raise ValueError(f"{f}: a non-numeric acceleration or angular rate") from None
            samples.append(farlio.ImuSample(stamp, w, a))
        return samples

    def _read_extrinsic(self) -> farlio.SE3:
        if self.options.calib is not None:
            return CalibFile(self.options.calib).T_imu_lidar("velodyne")
        for folder in (self.path, self.path.parent):
            if (folder / CALIB_FILE).exists():
                return read_imu_to_velo(folder / CALIB_FILE).inverse()
        if self._imu:
            self._warnings.append(
                f"{self.path}: no {CALIB_FILE} here or in the parent folder and no --calib: "
                f"assuming the Velodyne and OXTS frames coincide"
            )
        return farlio.SE3()

    def scan(self, i: int) -> farlio.Scan:
        scan = super().scan(i)
        if self._starts is not None:
            scan.start_stamp_ns = min(self._starts[i], scan.end_stamp_ns)
        return scan

    def imu(self) -> list[farlio.ImuSample]:
        return self._imu

    def groundtruth(self) -> Path | None:
        if not self._oxts_poses:
            return None
        if self._gt is None:
            scale = math.cos(math.radians(self._oxts_poses[0][0]))
            first_inv = np.linalg.inv(oxts_pose(self._oxts_poses[0], scale))
            traj = farlio.Trajectory()
            for stamp, p in zip(self._oxts_stamps, self._oxts_poses):
                traj.push_back(stamp, farlio.SE3.from_matrix(first_inv @ oxts_pose(p, scale)))
            self._gt = write_temporary_tum(traj, "farlio-kitti-raw-")
        return self._gt

    def T_imu_lidar(self) -> farlio.SE3:
        return self._T_imu_lidar

    def warnings(self) -> list[str]:
        return list(self._warnings)
