"""The dataset interface every dataloader implements."""

from __future__ import annotations

import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import farlio
from farlio import _core

from .pointcloud2 import TimeOptions


@dataclass
class LoadOptions:
    """What a dataloader may need beyond the path (all optional; `farlio run` options)."""

    #: PointCloud2 topics of a bag; several are merged into one scan per period of the first
    lidar_topics: list[str] = field(default_factory=list)
    #: sensor_msgs/Imu topic of a bag ('none': LiDAR-only)
    imu_topic: str | None = None
    #: calibration YAML with T_imu_lidar (used where the recording has no extrinsic)
    calib: Path | None = None
    #: per-point time field, unit, header stamp meaning of PointCloud2 messages
    time: TimeOptions = field(default_factory=TimeOptions)
    #: sensor metadata json of an Ouster pcap (default: the pcap's name with .json, or the only json beside it)
    meta: Path | None = None


class Dataset:
    """A recording: scans in time order, optional IMU, extrinsic and ground truth."""

    #: path the dataset was opened from
    path: Path

    @classmethod
    def matches(cls, path: Path) -> bool:  # pragma: no cover - interface
        raise NotImplementedError

    def __len__(self) -> int:  # pragma: no cover - interface
        raise NotImplementedError

    def scan(self, i: int) -> farlio.Scan:  # pragma: no cover - interface
        """Scan i with start/end stamps (ns) and, where recorded, per-point times."""
        raise NotImplementedError

    def scan_source(self, i: int) -> str:
        """Where scan i comes from (a file, a bag message), for error messages."""
        return f"{self.path} scan {i}"

    def imu(self) -> list[farlio.ImuSample]:
        """All IMU samples in time order (empty: LiDAR-only)."""
        return []

    def scan_end_stamps_ns(self) -> list[int] | None:
        """The end stamps of all scans when they are known without reading the scans (file names,
        times files), for the clock check before a run; None otherwise (bags, Ouster)."""
        return None

    def T_imu_lidar(self) -> farlio.SE3:
        """Maps LiDAR points into the IMU (body) frame; identity when unknown."""
        return farlio.SE3()

    def gravity_m_s2(self) -> float:
        """Local gravity; 9.81 unless the recording says otherwise."""
        return 9.81

    def groundtruth(self) -> Path | None:
        """A TUM file of true body poses (any rate), when the recording has one."""
        return None

    def groundtruth_scans(self) -> farlio.Trajectory | None:
        """True body poses at the scan end stamps, when the recording has them."""
        return None

    def groundtruth_scans_file(self) -> Path | None:
        """The TUM file groundtruth_scans() reads, when there is one (`farlio run` evaluates the
        scan poses against it rather than against groundtruth())."""
        return None

    def warnings(self) -> list[str]:
        return []

    @property
    def name(self) -> str:
        return Path(self.path).name


def write_temporary_tum(trajectory: farlio.Trajectory, prefix: str) -> Path:
    """A ground truth converted from a recording's own format, as groundtruth.tum in a new
    temporary folder (what Dataset.groundtruth returns)."""
    path = Path(tempfile.mkdtemp(prefix=prefix)) / "groundtruth.tum"
    _core.io.write_tum(path, trajectory)
    return path
