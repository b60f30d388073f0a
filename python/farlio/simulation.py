"""Writes generated sequences (farlio._core.sim) in the sequence folder format."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable

import farlio
from farlio import _core

#: the generator's profiles (docs/simulation.md)
PROFILES = ("racetrack", "urban", "handheld", "tunnel")
#: rate of groundtruth.tum (body poses); the scan-end poses are in groundtruth_scans.tum
GROUNDTRUTH_RATE_HZ = 100.0

#: IMU grades (docs/simulation.md): the profile's own IMU noise (default), an ideal IMU, datasheet classes
IMU_GRADES = ("profile", "ideal", "consumer", "industrial", "tactical")


def make_config(
    profile: str,
    *,
    seed: int = 1,
    duration_s: float | None = None,
    motion_start_s: float = 0.0,
    noise_free: bool = False,
    imu_grade: str = "profile",
    vibration: bool = True,
    **noise: float,
) -> Any:
    """The profile's defaults with the given overrides: the IMU set to imu_grade (with the platform
    vibration of the datasheet grades unless vibration=False), then the noise fields by their
    NoiseConfig name. motion_start_s > 0 begins the sequence that far into the profile's motion (a
    recording that starts while the body moves)."""
    cfg = _core.sim.default_config(profile)
    cfg.seed = seed
    if duration_s is not None:
        cfg.duration_s = duration_s
    cfg.motion_start_s = motion_start_s
    cfg.noise_free = noise_free
    cfg = _core.sim.apply_imu_grade(cfg, imu_grade, vibration)
    n = cfg.noise
    for name, value in noise.items():
        if value is None:
            continue
        if not hasattr(n, name):
            raise ValueError(f"unknown noise field '{name}'")
        setattr(n, name, value)
    cfg.noise = n
    return cfg


def write_sequence(
    config: Any,
    out_dir: Path,
    *,
    kitti: bool = False,
    encoding: str = "binary",
    on_scan: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Generates and writes a sequence folder (lidar/, imu.csv, calib.yaml, ground truth, meta.yaml;
    with kitti also velodyne/ + times.txt: the scans motion-compensated to the scan end, stamped at
    it, as KITTI odometry stores them). Returns timing figures."""
    gen = _core.sim.SequenceGenerator(config)
    w = _core.io.SequenceWriter(Path(out_dir))
    calib = _core.io.Calibration()
    calib.T_imu_lidar = gen.T_imu_lidar()
    calib.gravity_m_s2 = gen.gravity_m_s2()
    calib.imu_rate_hz = gen.imu_rate_hz()
    calib.lidar_rate_hz = gen.lidar_rate_hz()
    w.write_calibration(calib)
    w.write_imu(gen.imu())
    w.write_groundtruth(gen.groundtruth_body(GROUNDTRUTH_RATE_HZ))
    gt_scans = gen.groundtruth_scans()
    w.write_groundtruth_scans(gt_scans)
    w.write_groundtruth_kitti(gt_scans.transformed(gen.T_imu_lidar()))
    w.write_meta(gen.description())
    n = gen.num_scans()
    gen_s = 0.0
    points = 0
    stamps = []
    for i in range(n):
        t0 = time.perf_counter()
        scan = gen.scan(i)
        gen_s += time.perf_counter() - t0
        points += len(scan)
        w.write_scan(scan, encoding)
        if kitti:  # KITTI's scans are motion-compensated to their stamp (the scan end here)
            w.write_kitti_scan(gen.motion_compensated(scan), i)
        stamps.append(scan.end_stamp_ns)
        if on_scan:
            on_scan(i + 1, n)
    if kitti:
        w.write_kitti_times(stamps)
    return {"scans": n, "points_per_scan": points / max(n, 1), "generation_s_per_scan": gen_s / max(n, 1)}


def generate(profile: str, out_dir: Path, **kwargs: Any) -> dict[str, Any]:
    """make_config + write_sequence in one call (kwargs split between them)."""
    write_keys = {"kitti", "encoding", "on_scan"}
    cfg = make_config(profile, **{k: v for k, v in kwargs.items() if k not in write_keys})
    return write_sequence(cfg, out_dir, **{k: v for k, v in kwargs.items() if k in write_keys})


__all__ = ["GROUNDTRUTH_RATE_HZ", "IMU_GRADES", "PROFILES", "generate", "make_config", "write_sequence", "farlio"]
