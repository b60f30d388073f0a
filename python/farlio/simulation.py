"""Writes generated sequences (farlio._core.sim) in the sequence folder format."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

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


class Recording:
    """A generated recording held in memory (no files): scans, IMU, extrinsic, exact ground truth."""

    def __init__(self, config: Any):
        gen = _core.sim.SequenceGenerator(config)
        self.start_stamp_ns = config.start_stamp_ns
        self.scans = [gen.scan(i) for i in range(gen.num_scans())]
        self.imu = gen.imu()
        self.T_imu_lidar = gen.T_imu_lidar()
        self.gravity_m_s2 = gen.gravity_m_s2()
        self.gt_scans = gen.groundtruth_scans()
        self.gt_body = gen.groundtruth_body(GROUNDTRUTH_RATE_HZ)
        self.speed_at_start_m_s = float(np.linalg.norm(gen.state(config.start_stamp_ns).velocity_world_m_s))


def replay(rec: Recording, overrides: list[str], *, from_s: float = 0.0, fixed_latency_s: float = 0.02) -> dict:
    """The deterministic replay of `rec` (fixed latency) with config overrides "name=value"; the
    accuracy of its scan poses and 100 Hz odometry over the stamps from `from_s` seconds on (a
    stretch of the recording), what happened to its frames there, how the filter started, and
    how far its estimate of up is from the truth in its map frame at the end (deg)."""
    from .evaluation import make_options
    from .runner import replay_options

    config = _core.Config()
    for o in overrides:
        name, value = o.split("=", 1)
        config.set(name, value)
    imu = rec.imu if config.get("fusion.enabled") else []
    odo = _core.Odometry(config, rec.T_imu_lidar, rec.gravity_m_s2, imu, replay_options("fixed", fixed_latency_s))
    from_ns = rec.start_stamp_ns + round(from_s * 1e9)
    scans, odometry = _core.Trajectory(), _core.Trajectory()
    out = {"failed": 0, "map_restarts": 0, "first_output_s": math.nan}
    first_scan_ns = first_output_ns = None
    world_from_map = None  # the generator's world from the odometry's map frame (the first scan's)

    def take_odometry() -> None:
        nonlocal first_output_ns
        for stamp, pose in odo.take_odometry():
            first_output_ns = stamp if first_output_ns is None else first_output_ns
            if stamp >= from_ns:
                odometry.push_back(stamp, pose)

    for i, scan in enumerate(rec.scans):
        fr = odo.process(scan)
        take_odometry()
        if not fr.processed:
            continue
        if first_scan_ns is None:
            first_scan_ns = scan.end_stamp_ns
            world_from_map = rec.gt_scans[i][1].rotation() @ fr.body_pose.rotation().T
        if scan.end_stamp_ns >= from_ns:
            scans.push_back(scan.end_stamp_ns, fr.body_pose)
            out["failed"] += int(bool(fr.scan.failure))
            out["map_restarts"] += int(fr.scan.map_restarted)
    odo.finish(rec.scans[-1].end_stamp_ns)
    take_odometry()
    options = make_options()
    r = _core.eval.evaluate(scans, rec.gt_scans, options)
    out |= {
        "ape_m": r.ape.translation_m.rmse,
        "rpe_pct": r.kitti_rpe.translation_pct,
        "rot_deg": r.ape.rotation_deg.rmse,
    }
    out |= {"odom_ape_m": math.nan, "odom_rpe_pct": math.nan}
    if len(odometry) > 2:
        ro = _core.eval.evaluate(odometry, rec.gt_body, options)
        out |= {"odom_ape_m": ro.ape.translation_m.rmse, "odom_rpe_pct": ro.kitti_rpe.translation_pct}
    if first_output_ns is not None and first_scan_ns is not None:
        out["first_output_s"] = (first_output_ns - first_scan_ns) / 1e9
    stats = odo.fusion_stats
    if stats is not None:
        out["reinit"], out["rejected"] = stats.reinitializations, stats.lidar_groups_rejected
        out["initialization"] = stats.initialization
        true_up = world_from_map.T @ np.array([0.0, 0.0, 1.0])
        out["up_error_deg"] = math.degrees(math.acos(min(1.0, float(true_up @ np.asarray(stats.up_map)))))
        out["initial_up_error_deg"] = math.degrees(
            math.acos(min(1.0, float(true_up @ np.asarray(stats.initialization.up_map))))
        )
    return out


__all__ = [
    "GROUNDTRUTH_RATE_HZ",
    "IMU_GRADES",
    "PROFILES",
    "Recording",
    "generate",
    "make_config",
    "replay",
    "write_sequence",
    "farlio",
]
