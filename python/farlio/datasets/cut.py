"""A recording cut at a later start: what a bag cut mid-drive, or a node started while a recording
already plays, gives the odometry (`farlio run --start S`)."""

from __future__ import annotations

from pathlib import Path

import farlio
from farlio._core import NS_PER_S

from .base import Dataset


class StartCut(Dataset):
    """`inner` from `start_s` seconds after the start of its first readable scan on: the scans that
    start then or later and the IMU samples from then. Ground truth, calibration and the rest are
    the recording's own (the evaluation pairs poses by stamp)."""

    def __init__(self, inner: Dataset, start_s: float):
        if not start_s >= 0.0:
            raise ValueError(f"--start must be a number of seconds >= 0, got {start_s}")
        self.inner, self.start_s = inner, start_s
        self.path = inner.path
        self.cut_ns: int | None = None
        self.offset = len(inner)  # index of the first scan kept (none until found)
        self._skipped: list[str] = []
        for i in range(len(inner)):
            try:
                scan = inner.scan(i)
            except (ValueError, OSError) as e:  # before the cut it is not read again; after it, run reports it
                if self.cut_ns is not None:
                    self.offset = i
                    break
                self._skipped.append(f"{inner.scan_source(i)}: {e}")
                continue
            if self.cut_ns is None:
                self.cut_ns = scan.start_stamp_ns + round(start_s * NS_PER_S)
            if scan.start_stamp_ns >= self.cut_ns:
                self.offset = i
                break

    def __len__(self) -> int:
        return len(self.inner) - self.offset

    def scan(self, i: int) -> farlio.Scan:
        return self.inner.scan(self.offset + i)

    def scan_source(self, i: int) -> str:
        return self.inner.scan_source(self.offset + i)

    def imu(self) -> list[farlio.ImuSample]:
        if self.cut_ns is None:
            return []
        return [s for s in self.inner.imu() if s.stamp_ns >= self.cut_ns]

    def scan_end_stamps_ns(self) -> list[int] | None:
        stamps = self.inner.scan_end_stamps_ns()
        return None if stamps is None else stamps[self.offset :]

    def T_imu_lidar(self) -> farlio.SE3:
        return self.inner.T_imu_lidar()

    def gravity_m_s2(self) -> float:
        return self.inner.gravity_m_s2()

    def groundtruth(self) -> Path | None:
        return self.inner.groundtruth()

    def groundtruth_scans(self) -> farlio.Trajectory | None:
        return self.inner.groundtruth_scans()

    def groundtruth_scans_file(self) -> Path | None:
        return self.inner.groundtruth_scans_file()

    def warnings(self) -> list[str]:
        out = list(self.inner.warnings())
        out += [f"before the --start cut, unreadable: {w}" for w in self._skipped]
        if self.offset >= len(self.inner):
            out.append(f"{self.path}: no scan starts {self.start_s:g} s or more after the first one (--start)")
        return out

    @property
    def name(self) -> str:
        return f"{self.inner.name} from {self.start_s:g} s"
