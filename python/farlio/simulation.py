"""Writes generated sequences (farlio._core.sim) in the sequence folder format."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

import farlio
from farlio import _core

#: the generator's profiles (docs/simulation.md)
PROFILES = ("racetrack", "urban", "handheld", "tunnel", "garage")
#: rate of groundtruth.tum (body poses); the scan-end poses are in groundtruth_scans.tum
GROUNDTRUTH_RATE_HZ = 100.0

#: IMU grades (docs/simulation.md): the profile's own IMU noise (default), an ideal IMU, datasheet classes
IMU_GRADES = ("profile", "ideal", "consumer", "industrial", "tactical")
#: LiDAR models (docs/simulation.md): the profile's own sensors (default), Livox's non-repetitive
#: Avia and Mid-360, spinning heads of 16, 32 and 128 beams
LIDAR_MODELS = ("profile", "avia", "mid360", "vlp16", "hdl32", "os128")


def make_config(
    profile: str,
    *,
    seed: int = 1,
    duration_s: float | None = None,
    motion_start_s: float = 0.0,
    noise_free: bool = False,
    imu_grade: str = "profile",
    vibration: bool = True,
    lidar: str = "profile",
    lidar_rate_hz: float | None = None,
    imu_rate_hz: float | None = None,
    imu_time_offset_s: float = 0.0,
    **noise: float,
) -> Any:
    """The profile's defaults with the given overrides: the IMU set to imu_grade (with the platform
    vibration of the datasheet grades unless vibration=False), then the noise fields by their
    NoiseConfig name. motion_start_s > 0 begins the sequence that far into the profile's motion (a
    recording that starts while the body moves). lidar puts one sensor of a named model (LIDAR_MODELS)
    on the vehicle in place of the profile's own; lidar_rate_hz and imu_rate_hz replace the profile's
    rates; imu_time_offset_s puts the IMU's samples that long after the whole IMU periods of the
    sequence clock (below one period: between the fusion's steps)."""
    cfg = _core.sim.default_config(profile)
    cfg.seed = seed
    if duration_s is not None:
        cfg.duration_s = duration_s
    cfg.motion_start_s = motion_start_s
    cfg.noise_free = noise_free
    cfg.lidar_model = _core.sim.parse_lidar_model(lidar)
    if lidar_rate_hz is not None:
        cfg.lidar_rate_hz = lidar_rate_hz
    if imu_rate_hz is not None:
        cfg.imu_rate_hz = imu_rate_hz
    cfg.imu_time_offset_s = imu_time_offset_s
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


@dataclass
class ReplayRun:
    """A replay of a Recording: its trajectories and what happened to its frames."""

    rec: Recording
    scans: Any  # _core.Trajectory of the body poses at the scan ends
    odometry: Any  # _core.Trajectory of the 100 Hz fused odometry
    #: per processed frame: (scan end stamp, registration failed, map restarted after failures)
    frames: list[tuple[int, bool, bool]]
    first_scan_ns: int | None
    first_output_ns: int | None
    stats: Any  # FusionStats (None LiDAR-only)
    world_from_map: Any  # rotation: the generator's world from the odometry's map frame


def replay(rec: Recording, overrides: list[str], *, fixed_latency_s: float = 0.02) -> ReplayRun:
    """The deterministic replay of `rec` (fixed latency) with config overrides "name=value"."""
    from .runner import replay_options

    config = _core.Config()
    for o in overrides:
        name, value = o.split("=", 1)
        config.set(name, value)
    imu = rec.imu if config.get("fusion.enabled") else []
    odo = _core.Odometry(config, rec.T_imu_lidar, rec.gravity_m_s2, imu, replay_options("fixed", fixed_latency_s))
    run = ReplayRun(rec, _core.Trajectory(), _core.Trajectory(), [], None, None, None, None)

    def take_odometry() -> None:
        for stamp, pose in odo.take_odometry():
            run.first_output_ns = stamp if run.first_output_ns is None else run.first_output_ns
            run.odometry.push_back(stamp, pose)

    for i, scan in enumerate(rec.scans):
        fr = odo.process(scan)
        take_odometry()
        if not fr.processed:
            continue
        if run.first_scan_ns is None:
            run.first_scan_ns = scan.end_stamp_ns
            run.world_from_map = rec.gt_scans[i][1].rotation() @ fr.body_pose.rotation().T
        run.scans.push_back(scan.end_stamp_ns, fr.body_pose)
        run.frames.append((scan.end_stamp_ns, bool(fr.scan.failure), fr.scan.map_restarted))
    odo.finish(rec.scans[-1].end_stamp_ns)
    take_odometry()
    run.stats = odo.fusion_stats
    return run


def stretch_accuracy(run: ReplayRun, from_s: float = 0.0, to_s: float = math.inf) -> dict:
    """A replay's accuracy over the stretch [from_s, to_s] of its recording (s after its start): APE
    (aligned RMSE, m), KITTI-style RPE (%) and rotation RMSE (deg) of the scan poses and their
    rotation RMSE with the trajectories aligned at the stretch's first pose (evo's --align_origin:
    unlike the APE's rotation, after an alignment of the positions, it sees a roll about a nearly
    straight path, that is how the map frame was levelled), APE and RPE of
    the 100 Hz odometry, the frames that failed or restarted the map there; for the whole run, the
    first fused output after the first scan (s), how the filter started and how far its estimate of
    up is from the truth in the map frame, then and at the end (deg)."""
    from .evaluation import make_options

    t0 = run.rec.start_stamp_ns
    from_ns = t0 + round(from_s * 1e9)
    to_ns = t0 + round(to_s * 1e9) if math.isfinite(to_s) else np.iinfo(np.int64).max
    options = make_options()
    stretch = run.scans.between(from_ns, to_ns)
    r = _core.eval.evaluate(stretch, run.rec.gt_scans, options)
    out = {
        "ape_m": r.ape.translation_m.rmse,
        "rpe_pct": r.kitti_rpe.translation_pct,
        "rot_deg": r.ape.rotation_deg.rmse,
        "rot_origin_deg": _core.eval.evaluate(
            stretch, run.rec.gt_scans, make_options(align_origin=True)
        ).ape.rotation_deg.rmse,
    }
    inside = [f for f in run.frames if from_ns <= f[0] <= to_ns]
    out |= {"failed": sum(f[1] for f in inside), "map_restarts": sum(f[2] for f in inside)}
    out |= {"odom_ape_m": math.nan, "odom_rpe_pct": math.nan, "first_output_s": math.nan}
    odometry = run.odometry.between(from_ns, to_ns)
    if len(odometry) > 2:
        ro = _core.eval.evaluate(odometry, run.rec.gt_body, options)
        out |= {"odom_ape_m": ro.ape.translation_m.rmse, "odom_rpe_pct": ro.kitti_rpe.translation_pct}
    if run.first_output_ns is not None and run.first_scan_ns is not None:
        out["first_output_s"] = (run.first_output_ns - run.first_scan_ns) / 1e9
    if run.stats is not None:
        out["reinit"], out["rejected"] = run.stats.reinitializations, run.stats.lidar_groups_rejected
        out["initialization"] = run.stats.initialization
        true_up = run.world_from_map.T @ np.array([0.0, 0.0, 1.0])

        def off_deg(up: Any) -> float:
            return math.degrees(math.acos(min(1.0, float(true_up @ np.asarray(up)))))

        out["up_error_deg"] = off_deg(run.stats.up_map)
        out["initial_up_error_deg"] = off_deg(run.stats.initialization.up_map)
    return out


__all__ = [
    "GROUNDTRUTH_RATE_HZ",
    "IMU_GRADES",
    "PROFILES",
    "Recording",
    "generate",
    "make_config",
    "replay",
    "stretch_accuracy",
    "write_sequence",
    "farlio",
]
