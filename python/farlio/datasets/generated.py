"""A sequence of the generator served from memory, scan by scan: the same scans, IMU, extrinsic and
ground truth as `farlio simulate` writes, without the scans on disk (45 s of the urban drive is
1.1 GB of PCD, a racetrack lap about 7 GB). `farlio demo` runs on it; so do the figure scripts that
need long sequences (figures/harness.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import farlio
from farlio import _core
from farlio.datasets.base import Dataset
from farlio.simulation import GROUNDTRUTH_RATE_HZ, make_config


class GeneratedDataset(Dataset):
    """The sequence of `make_config(profile, seed=seed, duration_s=duration_s, **sim)`. Its ground
    truth at the scan ends is written to `folder`/groundtruth_scans.tum (what `farlio run` evaluates
    the scan poses against), and with `body_groundtruth` the body's at GROUNDTRUTH_RATE_HZ to
    `folder`/groundtruth.tum (for the 100 Hz odometry)."""

    def __init__(
        self,
        profile: str,
        seed: int,
        duration_s: float | None,
        folder: Path,
        body_groundtruth: bool = False,
        **sim: Any,
    ):
        self.gen = _core.sim.SequenceGenerator(make_config(profile, seed=seed, duration_s=duration_s, **sim))
        self.path = Path(folder)
        self.path.mkdir(parents=True, exist_ok=True)
        self.gt_scans = self.path / "groundtruth_scans.tum"
        _core.io.write_tum(self.gt_scans, self.gen.groundtruth_scans())
        self.gt_body: Path | None = None
        if body_groundtruth:
            self.gt_body = self.path / "groundtruth.tum"
            _core.io.write_tum(self.gt_body, self.gen.groundtruth_body(GROUNDTRUTH_RATE_HZ))

    def __len__(self) -> int:
        return self.gen.num_scans()

    def scan(self, i: int) -> farlio.Scan:
        return self.gen.scan(i)

    def scan_source(self, i: int) -> str:
        return f"generated scan {i}"

    def imu(self) -> list[farlio.ImuSample]:
        return self.gen.imu()

    def T_imu_lidar(self) -> farlio.SE3:
        return self.gen.T_imu_lidar()

    def gravity_m_s2(self) -> float:
        return self.gen.gravity_m_s2()

    def groundtruth(self) -> Path | None:
        return self.gt_body

    def groundtruth_scans_file(self) -> Path:
        return self.gt_scans
