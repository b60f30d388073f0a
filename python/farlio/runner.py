"""Runs the odometry over a dataset and writes its outputs as it goes.

Outputs in the output folder (every trajectory file names its frame):
  scans_lidar.tum        registered LiDAR pose at every scan end (TUM; flushed per frame)
  scans_body.tum         registered body (IMU) pose at every scan end = LiDAR pose * T_imu_lidar^-1
  odometry_body.tum      the fused 100 Hz body odometry (LIO only; flushed as it goes)
  scans_lidar_kitti.txt  LiDAR poses relative to the first (KITTI 3x4; flushed per frame)
  timing.csv             per-frame stage timings (stage_clock: wall or cuda_events), counts and what
                         happened to the frame (flushed)
  summary.json           frames, median/p99 latency, converged fraction, accuracy with ground truth;
                         written also when the run is interrupted (SIGINT, SIGTERM: "interrupted": true)
  config.yaml            the full effective parameter set
  eval_scans/, eval_odometry/   eval.json + eval.png against the ground truth, when there is one
  map.pcd, map.ply, map.png   the whole map (every scan whose pose was used, one centroid per cell
                         of the export resolution, with intensity), world frame, and its picture
                         from above (with --save-map; mapping.py)
  scans_lidar_global.tum, scans_body_global.tum, loops.csv   with --loop-closure: every scan's pose
                         after loop closure and the verified loop candidates (loop_closure.py);
                         eval_scans_global/ against the ground truth; with --save-map also
                         map_global.pcd, map_global.ply, map_global.png (the map at those poses)
  trajectory.png, latency.png   the estimated path (with ground truth) and the latency histogram (with plot)
"""

from __future__ import annotations

import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

import farlio
from farlio import _core
from farlio._core import NS_PER_S

from .config import config_to_yaml
from .datasets import Dataset
from .loop_closure import SCANS_BODY_GLOBAL_TUM, SCANS_LIDAR_GLOBAL_TUM, LoopClosure
from .mapping import MapOptions, WholeMap, load_prior_map, write_global_map
from .progress import Progress
from .timing_csv import MS_PER_S, TIMING_CSV, TimingCsv

#: values of --device and of the config field device
DEVICES = ("auto", "cpu", "cuda")
LATENCY_MODELS = {
    "measured": _core.LatencyModel.Measured,
    "zero": _core.LatencyModel.Zero,
    "fixed": _core.LatencyModel.Fixed,
}
CONFIG_YAML, SUMMARY_JSON = "config.yaml", "summary.json"
SCANS_LIDAR_TUM, SCANS_BODY_TUM, ODOMETRY_TUM = "scans_lidar.tum", "scans_body.tum", "odometry_body.tum"
SCANS_LIDAR_KITTI = "scans_lidar_kitti.txt"
EVAL_SCANS_DIR, EVAL_ODOMETRY_DIR, EVAL_GLOBAL_DIR = "eval_scans", "eval_odometry", "eval_scans_global"
MEDIAN_PERCENTILE, TAIL_PERCENTILE = 50, 99
#: fewer registered poses than this are not evaluated
MIN_EVALUATED_POSES = 3
BYTES_PER_MIB = 2**20


def _percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def _warn(msg: str) -> None:
    print(f"farlio: warning: {msg}", file=sys.stderr)


def replay_options(latency: str = "measured", fixed_latency_s: float = 0.0, added_delay_s: float = 0.0):
    """The latency model of the replay: 'measured' processing time, 'zero', or 'fixed'."""
    if latency not in LATENCY_MODELS:
        raise ValueError(f"unknown latency model '{latency}'; expected one of {', '.join(LATENCY_MODELS)}")
    o = _core.ReplayOptions()
    o.latency = LATENCY_MODELS[latency]
    o.fixed_latency_s = fixed_latency_s
    o.added_delay_s = added_delay_s
    return o


def run_dataset(
    dataset: Dataset,
    out_dir: Path,
    config: Any = None,
    *,
    max_frames: int | None = None,
    save_map: bool = False,
    maps: MapOptions | None = None,
    groundtruth: Path | None = None,
    progress: bool | None = None,
    plot: bool = True,
    options: Any = None,
    use_imu: bool = True,
    on_frame: Callable[[int, Any, Any], None] | None = None,
) -> dict[str, Any]:
    """Runs the odometry over `dataset` and writes the outputs listed in the module doc.

    use_imu False runs LiDAR-only even when the recording has an IMU; on_frame(i, scan, frame
    result) is called after every processed scan (a live view). save_map (or maps.save) writes the
    whole map; maps.prior_map localizes in a prior map (summary["localization"])."""
    maps = maps or MapOptions()
    maps.save = maps.save or save_map
    run = OdometryRun(dataset, Path(out_dir), config or _core.Config(), maps)
    run.open_outputs(options or replay_options(), use_imu)
    try:
        run.run_frames(max_frames, progress, on_frame)
    except KeyboardInterrupt:  # SIGINT, or SIGTERM through the CLI: what was done so far is kept
        run.write_summary(run.summarise() | {"interrupted": True})
        raise
    summary = run.summarise()
    if run.whole_map is not None:
        summary["map"] = run.whole_map.write(run.out_dir, run.out_dir / SCANS_LIDAR_TUM, plot)
    if run.loops is not None:
        summary["loop_closure"] = run.close_loops(plot)
    run.evaluate(summary, groundtruth, plot)
    if plot:
        run.plot(summary)
    run.write_summary(summary)
    return summary


@dataclass
class FrameCounts:
    """What happened to the frames so far."""

    totals_ms: list[float] = field(default_factory=list)  # processing time of every processed frame
    registered: int = 0
    fused: int = 0
    converged: int = 0
    skipped: int = 0
    dropped: int = 0  # not processed: the pipeline was busy
    not_fused: int = 0  # processed, its result not fused (timing.csv drop_reason: a failure, no IMU yet, ...)
    degenerate: int = 0  # registered frames with a degenerate direction
    failed: int = 0  # registrations whose pose was not used (too few inliers, non-finite)
    map_restarts: int = 0  # the map restarted after failures (recovery)
    lost: int = 0  # localization: scans that did not match the prior map
    last_lost: bool = False  # localization: the last processed scan did not


class OdometryRun:
    """The odometry over one dataset and the files it writes as it goes (run_dataset's steps)."""

    def __init__(self, dataset: Dataset, out_dir: Path, config: Any, maps: MapOptions | None = None):
        self.dataset, self.out_dir, self.config = dataset, out_dir, config
        self.maps = maps or MapOptions()
        self.whole_map = WholeMap(self.maps.resolution_m, out_dir) if self.maps.save else None
        self.loops: LoopClosure | None = None  # with --loop-closure, once the odometry exists
        self.prior_map_points = 0
        self.frames = 0
        self.counts = FrameCounts()
        self.lidar_poses = farlio.Trajectory()
        self.last_stamp: int | None = None
        self.wall_s = 0.0
        self.imu_span: tuple[int, int] | None = None  # first and last IMU stamp, when the IMU is used

    def open_outputs(self, options: Any, use_imu: bool) -> None:
        """config.yaml (written first so that a run that dies still says its parameters; rewritten
        at the end with the effective values), the odometry, and the trajectory files."""
        self.out_dir.mkdir(parents=True, exist_ok=True)
        (self.out_dir / CONFIG_YAML).write_text(config_to_yaml(self.config))
        for w in self.dataset.warnings():
            _warn(w)
        imu = self.dataset.imu() if use_imu else []
        if imu and self.config.get("fusion.enabled"):
            imu_stamps = [s.stamp_ns for s in imu]
            self.imu_span = (min(imu_stamps), max(imu_stamps))
            self.check_clocks()
        self.odo = _core.Odometry(self.config, self.dataset.T_imu_lidar(), self.dataset.gravity_m_s2(), imu, options)
        self.prior_map_points = load_prior_map(self.odo, self.maps)
        if self.maps.loop_closure:
            self.loops = LoopClosure(self.config, self.dataset.T_imu_lidar())
        self.warn_from_odometry()
        if self.odo.device_message:
            print(f"farlio: {self.odo.device_message}", file=sys.stderr)
        elif self.odo.device == "cuda":
            print(
                f"farlio: CUDA backend, {self.odo.map_memory_bytes / BYTES_PER_MIB:.0f} MiB of device memory "
                "preallocated",
                file=sys.stderr,
            )
        self.lidar_tum = _core.io.TrajectoryWriter(self.out_dir / SCANS_LIDAR_TUM)
        self.body_tum = _core.io.TrajectoryWriter(self.out_dir / SCANS_BODY_TUM)
        self.lidar_kitti = _core.io.TrajectoryWriter(self.out_dir / SCANS_LIDAR_KITTI, "kitti")
        self.odom_tum = _core.io.TrajectoryWriter(self.out_dir / ODOMETRY_TUM) if self.odo.inertial else None

    def clock_check(self, first_scan_ns: int, last_scan_ns: int) -> Any:
        """The IMU's stamp span against the scans' (_core.check_clocks)."""
        tolerance_s = self.config.get("fusion.imu_gate.max_bridged_gap_s")
        return _core.check_clocks(*self.imu_span, first_scan_ns, last_scan_ns, tolerance_s)

    def check_clocks(self) -> None:
        """Stops before the run when the IMU's stamps and the scans' do not overlap (different
        clocks or units: the error says which unit would fit); warns when the IMU starts late or
        ends early. Needs the scan stamps without reading the scans (folders; not bags, whose run
        warns at the end when no scan could be fused)."""
        stamps = self.dataset.scan_end_stamps_ns()
        if not stamps:
            return
        check = self.clock_check(min(stamps), max(stamps))
        if check.error:
            raise ValueError(f"{self.dataset.path}: {check.error}")
        for w in check.warnings:
            _warn(w)

    def warn_if_nothing_fused(self) -> None:
        """A run with an IMU in which no scan reached the fusion (its clock is not the scans')."""
        if self.imu_span is None or self.counts.fused or len(self.lidar_poses) == 0:
            return
        check = self.clock_check(self.lidar_poses[0][0], self.lidar_poses[len(self.lidar_poses) - 1][0])
        _warn("no scan was fused with the IMU" + (f": {check.error}" if check.error else ""))

    def warn_from_odometry(self) -> None:
        """What the odometry tolerated since the last call (sorted IMU, a reset of the fusion, the
        gyro's unit, an unusable IMU)."""
        for w in self.odo.take_warnings():
            _warn(w)

    def run_frames(
        self, max_frames: int | None, progress: bool | None, on_frame: Callable[[int, Any, Any], None] | None
    ) -> None:
        self.frames = len(self.dataset) if max_frames is None else min(len(self.dataset), max_frames)
        bar = Progress(self.frames, self.dataset.name, progress)
        start = time.perf_counter()
        try:
            with TimingCsv(self.out_dir / TIMING_CSV) as timing:
                for i in range(self.frames):
                    self.run_frame(i, timing, bar, on_frame)
                if self.last_stamp is not None:
                    self.odo.finish(self.last_stamp)
                    self.write_odometry()
        finally:
            bar.close()
            self.wall_s = time.perf_counter() - start
        self.warn_from_odometry()
        self.warn_if_nothing_fused()

    def run_frame(
        self, i: int, timing: TimingCsv, bar: Progress, on_frame: Callable[[int, Any, Any], None] | None
    ) -> None:
        scan = self.next_scan(i)
        if scan is None:
            return
        fr = self.odo.process(scan)
        self.last_stamp = scan.end_stamp_ns
        self.write_odometry()
        self.warn_from_odometry()
        timing.write(i, scan, fr)
        if not fr.processed:
            self.counts.dropped += 1
            return
        self.record(fr)
        if self.whole_map is not None:
            self.whole_map.add(self.odo, scan, fr)
        if self.loops is not None and not fr.scan.failure and not fr.scan.lost:
            self.loops.add(self.odo, scan, fr.scan)
        if on_frame is not None:
            on_frame(i, scan, fr)
        bar.update(i + 1, f"{fr.scan.timings.total_s * MS_PER_S:6.1f} ms")

    def next_scan(self, i: int) -> Any:
        """Scan i without non-finite points; None (counted as skipped, with a warning) when it
        cannot be read (the loaders also refuse per-point times that are not seconds since the
        scan start) or does not come after the previous one."""
        try:
            scan = self.dataset.scan(i)
        except (ValueError, OSError) as e:
            self.counts.skipped += 1
            _warn(f"skipping {self.dataset.scan_source(i)}: {e}")
            return None
        if self.last_stamp is not None and scan.end_stamp_ns <= self.last_stamp:
            self.counts.skipped += 1
            _warn(
                f"skipping {self.dataset.scan_source(i)}: its stamp {scan.end_stamp_ns} ns is not after the "
                f"previous scan's {self.last_stamp} ns (time going backwards)"
            )
            return None
        removed = scan.remove_non_finite()
        if removed:
            _warn(f"{self.dataset.scan_source(i)}: dropped {removed} points with NaN/Inf coordinates or times")
        return scan

    def write_odometry(self) -> None:
        """The 100 Hz odometry produced since the last call (LIO only)."""
        if self.odom_tum is not None:
            for stamp, pose in self.odo.take_odometry():
                self.odom_tum.append(stamp, pose)

    def record(self, fr: Any) -> None:
        """The poses and counts of a processed frame."""
        r = fr.scan
        self.lidar_tum.append(r.stamp_ns, r.pose)
        self.body_tum.append(r.stamp_ns, fr.body_pose)
        first = self.lidar_poses[0][1] if len(self.lidar_poses) else r.pose
        self.lidar_kitti.append(r.stamp_ns, first.inverse() * r.pose)  # relative to the first
        self.lidar_poses.push_back(r.stamp_ns, r.pose)
        self.counts.totals_ms.append(r.timings.total_s * MS_PER_S)
        self.counts.registered += int(r.registered)
        self.counts.fused += int(fr.fused)
        self.counts.converged += int(r.registered and r.converged and not r.failure)
        self.counts.failed += int(bool(r.failure))
        self.counts.map_restarts += int(r.map_restarted)
        self.counts.lost += int(r.lost)
        self.counts.last_lost = r.lost
        self.counts.not_fused += int(self.odo.inertial and bool(fr.drop_reason))
        self.counts.degenerate += int(fr.degeneracy is not None and fr.degeneracy.degenerate)

    def summarise(self) -> dict[str, Any]:
        c, totals = self.counts, self.counts.totals_ms
        summary = {
            "dataset": str(self.dataset.path),
            "mode": "lidar-inertial" if self.odo.inertial else "lidar-only",
            "frames": self.frames,
            "processed": len(totals),
            "skipped": c.skipped,
            "dropped": c.dropped,
            "registered": c.registered,
            "fused": c.fused,
            "not_fused": c.not_fused,
            "degenerate": c.degenerate,
            "registration_failed": c.failed,
            "map_restarts": c.map_restarts,
            "converged_fraction": c.converged / c.registered if c.registered else float("nan"),
            "latency_ms": {
                "median": _percentile(totals, MEDIAN_PERCENTILE),
                "p99": _percentile(totals, TAIL_PERCENTILE),
                "max": max(totals) if totals else float("nan"),
                "mean": float(np.mean(totals)) if totals else float("nan"),
            },
            "wall_s": self.wall_s,
            "rate_hz": len(totals) / self.wall_s if self.wall_s > 0 else float("nan"),
            "device": self.odo.device,
            "map_memory_bytes": self.odo.map_memory_bytes,
            "threads": self.config.get("num_threads"),
        }
        stats = self.odo.fusion_stats
        if stats is not None:
            summary["fusion"] = _fusion_summary(stats, self.config)
            init = summary["fusion"]["initialization"]
            if init["stamp_ns"] is not None and len(self.lidar_poses):
                init["after_first_scan_s"] = (init["stamp_ns"] - self.lidar_poses[0][0]) / NS_PER_S
        if self.maps.prior_map is not None:
            summary["localization"] = {
                "prior_map": str(self.maps.prior_map),
                "prior_map_points": self.prior_map_points,
                "initial_pose": list(self.maps.initial_pose) if self.maps.initial_pose is not None else None,
                "frames_localized": len(totals) - c.lost,
                "frames_lost": c.lost,
                "localized_at_end": bool(totals) and not c.last_lost,
                # a run lost in most of its scans has not localized (a wrong map or initial pose)
                "localized": len(totals) > 2 * c.lost,
            }
        return summary

    def close_loops(self, plot: bool) -> dict[str, Any]:
        """The last keyframe's search, the global trajectory and loops.csv (and the global map with
        --save-map); returns the summary's "loop_closure" entry."""
        self.loops.finish()
        summary = self.loops.write(self.out_dir)
        if self.whole_map is not None:
            resolution = self.maps.resolution_m or _core.export_resolution_m(self.odo.effective_config)
            summary["map"] = write_global_map(
                self.loops, resolution, self.out_dir, self.out_dir / SCANS_LIDAR_GLOBAL_TUM, plot
            )
        return summary

    def evaluate(self, summary: dict[str, Any], groundtruth: Path | None, plot: bool) -> None:
        """Accuracy of the scan poses and of the 100 Hz odometry against the ground truth, when there
        is one: eval_scans/, eval_odometry/ and summary["accuracy"], summary["accuracy_odometry"]."""
        from .evaluation import evaluate_files

        if len(self.lidar_poses) < MIN_EVALUATED_POSES:
            return
        gt_scans = groundtruth
        if gt_scans is None:
            gt_scans = self.dataset.groundtruth_scans_file()
        if gt_scans is None:
            gt_scans = self.dataset.groundtruth()  # a dense ground truth (MulRan): interpolated at the scan stamps
        if gt_scans is not None:
            summary["accuracy"] = evaluate_files(
                self.out_dir / SCANS_BODY_TUM, Path(gt_scans), self.out_dir / EVAL_SCANS_DIR, plot=plot
            )
            if self.loops is not None and len(self.loops.keyframes):
                summary["accuracy_global"] = evaluate_files(
                    self.out_dir / SCANS_BODY_GLOBAL_TUM, Path(gt_scans), self.out_dir / EVAL_GLOBAL_DIR, plot=plot
                )
        gt_dense = groundtruth or self.dataset.groundtruth()
        if gt_dense is not None and self.odom_tum is not None and len(self.odom_tum) >= MIN_EVALUATED_POSES:
            summary["accuracy_odometry"] = evaluate_files(
                self.out_dir / ODOMETRY_TUM, Path(gt_dense), self.out_dir / EVAL_ODOMETRY_DIR, plot=plot
            )

    def plot(self, summary: dict[str, Any]) -> None:
        """trajectory.png and latency.png, when a frame was processed."""
        if self.counts.totals_ms:
            from .plots import plot_run

            plot_run(self.out_dir, summary.get("accuracy", {}).get("groundtruth_file"))

    def write_summary(self, summary: dict[str, Any]) -> None:
        """config.yaml with the effective parameters (the voxel size is fixed at the first scan) and
        summary.json."""
        effective = self.odo.effective_config
        (self.out_dir / CONFIG_YAML).write_text(config_to_yaml(effective))
        summary["voxel_size_m"] = float(effective.get("map.voxel_size_m"))
        (self.out_dir / SUMMARY_JSON).write_text(json.dumps(summary, indent=2, default=_json_default))


def _fusion_summary(stats: Any, config: Any) -> dict[str, Any]:
    """The fusion's counters for summary.json; warns about an accelerometer in g and IMU gaps."""
    if stats.accel_in_g:
        _warn(stats.accel_unit_message)
    if stats.imu_gaps:
        _warn(
            f"{stats.imu_gaps} IMU gap(s): no sample for longer than fusion.imu_gate.gap_limit_s "
            "(the last input was held)"
        )
    if stats.imu_samples_rejected:
        _warn(
            f"{stats.imu_samples_rejected} IMU sample(s) rejected as non-finite, impossible or spikes "
            f"(fusion.imu_gate.max_*, fusion.imu_gate.spike_*); the last: {stats.last_warning}"
        )
    init = stats.initialization
    up = np.asarray(stats.up_map, dtype=float)
    return {
        # how the filter started: at rest, or in motion from the LiDAR results of its first scans
        "initialization": {
            "mode": init.mode or None,
            "stamp_ns": init.stamp_ns if init.initialized else None,
            "window_s": init.window_s,
            "window_scans": init.window_poses,
            "speed_m_s": init.speed_m_s,
            "gravity_norm_error": init.gravity_norm_error,
        },
        # the output frame's z axis against up, as the filter estimates it at the end
        "world_tilt_deg": math.degrees(math.acos(max(-1.0, min(1.0, float(up[2]))))),
        "lidar_groups_accepted": stats.lidar_groups_accepted,
        "lidar_groups_rejected": stats.lidar_groups_rejected,
        "reinitializations": stats.reinitializations,
        "imu_gaps": stats.imu_gaps,
        "imu_samples_dropped": stats.imu_samples_dropped,
        "imu_samples_rejected": stats.imu_samples_rejected,
        "accel_in_g": stats.accel_in_g,
        "gyro_bias_rad_s": list(stats.gyro_bias_rad_s),
        "accel_bias_m_s2": list(stats.accel_bias_m_s2),
        # the IMU as measured on its samples; the filter's input noise is the larger of this and
        # fusion.gyro_input_std_rad_s / accel_input_std_m_s2
        "imu": {
            "rate_hz": stats.imu_rate_hz,
            "step_s": config.get("fusion.step_s"),
            "gyro_step_std_rad_s": stats.measured_gyro_step_std_rad_s,
            "accel_step_std_m_s2": stats.measured_accel_step_std_m_s2,
            "gyro_input_std_rad_s": config.get("fusion.gyro_input_std_rad_s"),
            "accel_input_std_m_s2": config.get("fusion.accel_input_std_m_s2"),
            # the gyro's mean weight in the rotation rate that undistorts the scans, per LiDAR axis
            # (1: the gyro's rate, 0: the LiDAR's constant twist): the two blended by their errors
            "deskew_gyro_weight": list(stats.deskew_gyro_weight),
        },
        # the LiDAR updates' normalised innovations squared (NIS) per degree of freedom: 1 and 5 %
        # beyond the chi-squared 95 % quantile when the filter's noise fits the data
        "innovation": {
            s.group: {
                "dof": s.dim,
                "count": s.count,
                "mean_nis_per_dof": s.mean_per_dof,
                "share_beyond_95": s.share_beyond_95,
            }
            for s in stats.lidar_innovation
        },
    }


#: an IMU below this share of the filter's step rate is said to be slower than it (a 100 Hz IMU's
#: measured rate scatters by a few tenths of a hertz about the step's)
SLOWER_THAN_STEP_SHARE = 0.9


def _imu_lines(imu: dict[str, float]) -> list[str]:
    """One line each where the IMU is slower than the filter's step or noisier than its defaults."""
    lines = []
    step_s = imu["step_s"]
    if 0.0 < imu["rate_hz"] < SLOWER_THAN_STEP_SHARE / step_s:
        lines.append(
            f"IMU at {imu['rate_hz']:.0f} Hz, slower than the filter's {1.0 / step_s:.0f} Hz step: its samples are "
            f"interpolated between the steps, and the {1.0 / step_s:.0f} Hz output follows the newest sample "
            f"(up to {1e3 / imu['rate_hz']:.0f} ms after its instant)"
        )
    noisier = [
        f"{name} {imu[measured]:.3g} {unit} (fusion.{floor} {imu[floor]:.3g})"
        for name, measured, unit, floor in (
            ("gyro", "gyro_step_std_rad_s", "rad/s", "gyro_input_std_rad_s"),
            ("accelerometer", "accel_step_std_m_s2", "m/s^2", "accel_input_std_m_s2"),
        )
        if imu[measured] > imu[floor]
    ]
    if noisier:
        lines.append(
            f"IMU noise over a {1e3 * step_s:.0f} ms step, measured on its samples: "
            + ", ".join(noisier)
            + ": the filter uses the measured noise"
        )
    return lines


def _json_default(o: Any) -> Any:
    if isinstance(o, float) and math.isnan(o):
        return None
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    raise TypeError(f"not JSON serialisable: {type(o)}")


def format_summary(s: dict[str, Any]) -> str:
    lat = s["latency_ms"]
    frac = s["converged_fraction"]
    converged = "no scan registered yet" if frac is None or math.isnan(frac) else f"{100 * frac:.1f}%"
    lines = [
        f"{s['mode']}: frames {s['processed']}/{s['frames']} (skipped {s['skipped']}, dropped "
        f"{s['dropped']}), converged {converged}, {s['rate_hz']:.1f} Hz overall",
        f"latency per frame: median {lat['median']:.2f} ms, p99 {lat['p99']:.2f} ms, max {lat['max']:.2f} ms",
    ]
    if s.get("registration_failed"):
        lines.append(
            f"registration failed on {s['registration_failed']} scans (kept the prediction; timing.csv drop_reason), "
            f"map restarts {s.get('map_restarts', 0)}"
        )
    init = s.get("fusion", {}).get("initialization")
    if init is not None:
        if init["mode"] is None:
            degenerate = s.get("degenerate", 0)
            why = (
                f"{degenerate} of {s['processed']} scans had a degenerate direction, and the filter starts from "
                "scans that constrain every direction"
                if degenerate
                else "no LiDAR results with the IMU between them"
            )
            lines.append(f"fusion: never initialised ({why}): LiDAR-only scan poses, no 100 Hz odometry")
        else:
            tilt = s["fusion"]["world_tilt_deg"]
            lines.append(
                f"fusion: initialised {init['mode']}, {init.get('after_first_scan_s', 0.0):.2f} s after the first scan "
                f"({init['window_scans']} scans, {init['speed_m_s']:.1f} m/s); world z {tilt:.1f} deg from up"
            )
        lines.extend(_imu_lines(s["fusion"]["imu"]))
    loc = s.get("localization")
    if loc:
        lines.append(
            f"localization in {loc['prior_map']}: {loc['frames_localized']} scans localized, {loc['frames_lost']} lost "
            "(timing.csv lost, inlier_fraction)"
        )
    if s.get("map"):
        m = s["map"]
        lines.append(f"map: {m['points']} points at {m['resolution_m'] or 0:.2f} m (map.pcd, map.ply, map.png)")
    if s.get("loop_closure"):
        lc = s["loop_closure"]
        lines.append(
            f"loop closure: {lc['accepted']} of {lc['candidates']} verified loops accepted ({lc['in_graph']} "
            f"corrected the graph) over {lc['keyframes']} keyframes (scans_body_global.tum, loops.csv), "
            f"{lc['verify_s']:.1f} s verifying"
        )
    for key, label in (
        ("accuracy", "scan poses"),
        ("accuracy_odometry", "100 Hz odometry"),
        ("accuracy_global", "scan poses after loop closure"),
    ):
        if s.get(key):
            lines.append(f"{label}: {_accuracy_line(s[key])}")
    return "\n".join(lines)


def _accuracy_line(acc: dict[str, Any]) -> str:
    try:
        ape = acc["ape"]["translation_m"]["rmse"]
        kitti = acc["kitti_rpe"]
        return (
            f"APE {ape:.3f} m (aligned RMSE), RPE {kitti['translation_pct']:.3f} % / "
            f"{kitti['rotation_deg_per_100m']:.3f} deg/100m, coverage {100 * acc['coverage']:.1f}%"
        )
    except (KeyError, TypeError):
        return "see eval.json"
