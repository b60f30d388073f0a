"""Dataloaders for folders: the sequence folder format, KITTI odometry, plain point cloud folders."""

from __future__ import annotations

from pathlib import Path

import farlio
from farlio import _core

from .base import Dataset, LoadOptions, write_temporary_tum

POINT_CLOUD_SUFFIXES = (".pcd", ".pcd.gz", ".ply", ".bin")
#: a sequence folder's body poses at the scan end stamps
GROUNDTRUTH_SCANS_TUM = "groundtruth_scans.tum"
#: LiDAR poses at the scan stamps relative to the first, KITTI 3x4 (`farlio simulate --kitti`)
GROUNDTRUTH_KITTI = "groundtruth_kitti.txt"
#: Scan period assumed for folders without stamps (10 Hz, the common spinning-LiDAR rate).
DEFAULT_PERIOD_NS = 100_000_000


def _is_cloud(p: Path) -> bool:
    return p.is_file() and any(p.name.endswith(s) for s in POINT_CLOUD_SUFFIXES)


def _with_stamps(scan: farlio.Scan, start_ns: int, end_ns: int) -> farlio.Scan:
    scan.start_stamp_ns = start_ns
    scan.end_stamp_ns = end_ns
    return scan


class SequenceFolder(Dataset):
    """The neutral sequence folder (docs/sequence-folder.md): lidar/, imu.csv, calib.yaml, ground truth."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        return (path / "lidar").is_dir()

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self._reader = _core.io.SequenceReader(self.path)

    def __len__(self) -> int:
        return self._reader.num_scans()

    def scan(self, i: int) -> farlio.Scan:
        return self._reader.read_scan(i)

    def scan_source(self, i: int) -> str:
        return str(self._reader.scan_path(i))

    def scan_end_stamps_ns(self) -> list[int] | None:
        return [self._reader.scan_end_stamp_ns(i) for i in range(len(self))]

    def imu(self) -> list[farlio.ImuSample]:
        return self._reader.imu() if self._reader.has_imu() else []

    def T_imu_lidar(self) -> farlio.SE3:
        return self._reader.calibration().T_imu_lidar

    def gravity_m_s2(self) -> float:
        return self._reader.calibration().gravity_or_default()

    def groundtruth(self) -> Path | None:
        p = self.path / "groundtruth.tum"
        return p if p.exists() else None

    def groundtruth_scans(self) -> farlio.Trajectory | None:
        return self._reader.groundtruth_scans()

    def groundtruth_scans_file(self) -> Path | None:
        p = self.path / GROUNDTRUTH_SCANS_TUM
        return p if p.exists() else None

    def warnings(self) -> list[str]:
        return list(self._reader.warnings())


class _FilesWithStamps(Dataset):
    """One file a scan (self._files) with end stamps (self._stamps, ns)."""

    _files: list[Path]
    _stamps: list[int]

    def __len__(self) -> int:
        return len(self._files)

    def scan(self, i: int) -> farlio.Scan:
        """Scan i, starting one period before its stamp (the gap to the previous stamp; for the
        first scan the gap to the next, as SequenceReader does); its per-point times are checked
        (_core.io.check_point_times, the check of every loader)."""
        if i > 0:
            period = self._stamps[i] - self._stamps[i - 1]
        elif len(self._stamps) > 1:
            period = self._stamps[1] - self._stamps[0]
        else:
            period = DEFAULT_PERIOD_NS
        scan = _with_stamps(_core.io.read_point_cloud(self._files[i]), self._stamps[i] - period, self._stamps[i])
        _core.io.check_point_times(scan, str(self._files[i]))
        return scan

    def scan_source(self, i: int) -> str:
        return str(self._files[i])

    def scan_end_stamps_ns(self) -> list[int] | None:
        return list(self._stamps)


class KittiOdometry(_FilesWithStamps):
    """A KITTI odometry sequence: velodyne/NNNNNN.bin and times.txt (seconds). Scan k is stamped
    times.txt[k], start and end alike: KITTI's scans are motion-compensated to that instant (no
    per-point time), and its ground truth poses/XX.txt puts frame k there too. Without times.txt
    scan k is at k * DEFAULT_PERIOD_NS, as read_kitti stamps poses without a times file.
    Ground truth: groundtruth_kitti.txt (LiDAR poses, as `farlio simulate --kitti` writes them)
    stamped by times.txt; KITTI's own poses/XX.txt are camera poses and are not read."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        return (path / "velodyne").is_dir()

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self._files = sorted(p for p in (self.path / "velodyne").iterdir() if p.suffix == ".bin")
        if not self._files:
            raise ValueError(f"{self.path / 'velodyne'}: no .bin scans")
        times = self.path / "times.txt"
        if times.exists():
            self._stamps = list(_core.io.read_stamps(times))
            if len(self._stamps) != len(self._files):
                raise ValueError(f"{times}: {len(self._stamps)} stamps for {len(self._files)} scans in velodyne/")
        else:
            self._stamps = [i * DEFAULT_PERIOD_NS for i in range(len(self._files))]
        self._gt: Path | None = None

    def scan(self, i: int) -> farlio.Scan:
        scan = _with_stamps(_core.io.read_point_cloud(self._files[i]), self._stamps[i], self._stamps[i])
        _core.io.check_point_times(scan, str(self._files[i]))
        return scan

    def groundtruth(self) -> Path | None:
        src = self.path / GROUNDTRUTH_KITTI
        if not src.exists():
            return None
        if self._gt is None:  # one pose a scan (InputError otherwise)
            self._gt = write_temporary_tum(_core.io.read_kitti(src, self._stamps), "farlio-kitti-")
        return self._gt


class PointCloudFolder(_FilesWithStamps):
    """A folder of .pcd/.pcd.gz/.ply/.bin files, one scan each, in name order. Stamps: the file
    name when it is an integer (ns), else DEFAULT_PERIOD_NS apart."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        return path.is_dir() and any(_is_cloud(p) for p in path.iterdir())

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self._files = sorted(p for p in self.path.iterdir() if _is_cloud(p))
        stems = [p.name.split(".")[0] for p in self._files]
        if all(s.isdigit() and len(s) > 12 for s in stems):
            self._stamps = [int(s) for s in stems]
        else:
            self._stamps = [(i + 1) * DEFAULT_PERIOD_NS for i in range(len(self._files))]
