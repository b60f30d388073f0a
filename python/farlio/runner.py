"""Runs the odometry over a dataset and writes its outputs as it goes.

Outputs in the output folder (every trajectory file names its frame):
  scans_lidar.tum        registered LiDAR pose at every scan end (TUM; flushed per frame)
  scans_body.tum         registered body (IMU) pose at every scan end = LiDAR pose * T_imu_lidar^-1
  odometry_body.tum      the fused 100 Hz body odometry (LIO only; flushed as it goes)
  scans_lidar_kitti.txt  LiDAR poses relative to the first (KITTI 3x4), written at the end
  timing.csv             per-frame stage timings (stage_clock: wall or cuda_events), counts and what
                         happened to the frame (flushed)
  summary.json           frames, median/p99 latency, converged fraction, accuracy with ground truth
  config.yaml            the full effective parameter set
  eval_scans/, eval_odometry/   eval.json + eval.png against the ground truth, when there is one
  map.ply, map.pcd       the final submap, world frame (with --save-map)
  trajectory.png, latency.png   the estimated path (with ground truth) and the latency histogram (with plot)
"""
from __future__ import annotations

import csv
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

import farlio
from farlio import _core

from .config import config_to_yaml
from .datasets import Dataset
from .progress import Progress

MS_PER_S = 1e3
#: values of --device and of the config field device
DEVICES = ("auto", "cpu", "cuda")
#: timing.csv's stage_clock: the stage times are wall clock (CPU) or CUDA events (GPU timeline)
STAGE_CLOCKS = {False: "wall", True: "cuda_events"}
TIMING_COLUMNS = ["frame", "stamp_ns", "input_points", "kept_points", "source_points", "registered", "converged",
                  "iterations", "inliers", "sigma_m", "density_limit", "map_voxels", "map_points",
                  "preprocess_ms", "covariance_ms", "registration_ms", "map_update_ms", "total_ms",
                  "stage_clock", "fused", "guess_from_fusion", "latency_ms", "drop_reason"]
LATENCY_MODELS = {"measured": _core.LatencyModel.Measured, "zero": _core.LatencyModel.Zero,
                  "fixed": _core.LatencyModel.Fixed}


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


def run_dataset(dataset: Dataset, out_dir: Path, config: Any = None, *, max_frames: int | None = None,
                save_map: bool = False, groundtruth: Path | None = None, progress: bool | None = None,
                plot: bool = True, options: Any = None, use_imu: bool = True,
                on_frame: Callable[[int, Any, Any], None] | None = None) -> dict[str, Any]:
    """Runs the odometry over `dataset` and writes the outputs listed in the module doc.

    use_imu False runs LiDAR-only even when the recording has an IMU; on_frame(i, scan, frame
    result) is called after every processed scan (a live view)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    config = config or _core.Config()
    # written first so that a run that dies still says its parameters; rewritten at the end
    # with the effective values (the voxel size is fixed at the first scan)
    (out_dir / "config.yaml").write_text(config_to_yaml(config))
    for w in dataset.warnings():
        _warn(w)

    T_imu_lidar = dataset.T_imu_lidar()
    imu = dataset.imu() if use_imu else []
    odo = _core.Odometry(config, T_imu_lidar, dataset.gravity_m_s2(), imu, options or replay_options())
    if odo.device_message:
        print(f"farlio: {odo.device_message}", file=sys.stderr)
    elif odo.device == "cuda":
        print(f"farlio: CUDA backend, {odo.map_memory_bytes / 2**20:.0f} MiB of device memory preallocated",
              file=sys.stderr)
    lidar_tum = _core.io.TrajectoryWriter(out_dir / "scans_lidar.tum")
    body_tum = _core.io.TrajectoryWriter(out_dir / "scans_body.tum")
    odom_tum = _core.io.TrajectoryWriter(out_dir / "odometry_body.tum") if odo.inertial else None
    lidar_traj = farlio.Trajectory()

    n = len(dataset) if max_frames is None else min(len(dataset), max_frames)
    totals_ms: list[float] = []
    converged = registered = skipped = dropped = 0
    last_stamp = None
    bar = Progress(n, dataset.name, progress)
    start = time.perf_counter()
    with open(out_dir / "timing.csv", "w", newline="", buffering=1) as f:
        writer = csv.writer(f)
        writer.writerow(TIMING_COLUMNS)
        for i in range(n):
            try:
                scan = dataset.scan(i)
            except (ValueError, OSError) as e:
                skipped += 1
                _warn(f"skipping {dataset.scan_source(i)}: {e}")
                continue
            if last_stamp is not None and scan.end_stamp_ns <= last_stamp:
                skipped += 1
                _warn(f"skipping {dataset.scan_source(i)}: its stamp {scan.end_stamp_ns} ns is not after the "
                      f"previous scan's {last_stamp} ns (time going backwards)")
                continue
            removed = scan.remove_non_finite()
            if removed:
                _warn(f"{dataset.scan_source(i)}: dropped {removed} points with NaN/Inf coordinates or times")
            fr = odo.process(scan)
            last_stamp = scan.end_stamp_ns
            if odom_tum is not None:
                for stamp, pose in odo.take_odometry():
                    odom_tum.append(stamp, pose)
            if not fr.processed:
                dropped += 1
                writer.writerow([i, scan.end_stamp_ns] + [""] * (len(TIMING_COLUMNS) - 3) + [fr.drop_reason])
                continue
            r = fr.scan
            lidar_tum.append(r.stamp_ns, r.pose)
            body_tum.append(r.stamp_ns, fr.body_pose)
            lidar_traj.push_back(r.stamp_ns, r.pose)
            t = r.timings
            totals_ms.append(t.total_s * MS_PER_S)
            registered += int(r.registered)
            converged += int(r.registered and r.converged)
            dropped += int(bool(fr.drop_reason))
            writer.writerow([i, r.stamp_ns, r.input_points, r.kept_points, r.source_points, int(r.registered),
                             int(r.converged), r.iterations, r.inliers, f"{r.sigma_m:.4f}", r.density_limit,
                             r.map_voxels, r.map_points] +
                            [f"{v * MS_PER_S:.3f}" for v in (t.preprocess_s, t.covariance_s, t.registration_s,
                                                             t.map_update_s, t.total_s)] +
                            [STAGE_CLOCKS[t.device_timed], int(fr.fused), int(fr.guess_from_fusion),
                             f"{(fr.available_ns - fr.started_ns) / 1e6:.3f}", fr.drop_reason])
            if on_frame is not None:
                on_frame(i, scan, fr)
            bar.update(i + 1, f"{t.total_s * MS_PER_S:6.1f} ms")
        if last_stamp is not None:
            odo.finish(last_stamp)
            if odom_tum is not None:
                for stamp, pose in odo.take_odometry():
                    odom_tum.append(stamp, pose)
    bar.close()
    wall_s = time.perf_counter() - start

    if len(lidar_traj) > 0:
        first_inv = lidar_traj[0][1].inverse()
        rel = farlio.Trajectory()
        for k in range(len(lidar_traj)):
            stamp, pose = lidar_traj[k]
            rel.push_back(stamp, first_inv * pose)
        _core.io.write_kitti(out_dir / "scans_lidar_kitti.txt", rel)
    if save_map:
        submap = farlio.Scan(odo.map_points())
        _core.io.write_ply(out_dir / "map.ply", submap)
        _core.io.write_pcd(out_dir / "map.pcd", submap)

    summary: dict[str, Any] = {
        "dataset": str(dataset.path),
        "mode": "lidar-inertial" if odo.inertial else "lidar-only",
        "frames": n,
        "processed": len(totals_ms),
        "skipped": skipped,
        "dropped": dropped,
        "registered": registered,
        "converged_fraction": converged / registered if registered else float("nan"),
        "latency_ms": {"median": _percentile(totals_ms, 50), "p99": _percentile(totals_ms, 99),
                       "max": max(totals_ms) if totals_ms else float("nan"),
                       "mean": float(np.mean(totals_ms)) if totals_ms else float("nan")},
        "wall_s": wall_s,
        "rate_hz": len(totals_ms) / wall_s if wall_s > 0 else float("nan"),
        "device": odo.device,
        "map_memory_bytes": odo.map_memory_bytes,
        "threads": config.get("num_threads"),
    }
    stats = odo.fusion_stats
    if stats is not None:
        summary["fusion"] = {"lidar_groups_accepted": stats.lidar_groups_accepted,
                             "lidar_groups_rejected": stats.lidar_groups_rejected,
                             "reinitializations": stats.reinitializations, "imu_gaps": stats.imu_gaps,
                             "imu_samples_dropped": stats.imu_samples_dropped, "accel_in_g": stats.accel_in_g,
                             "gyro_bias_rad_s": list(stats.gyro_bias_rad_s)}
        if stats.accel_in_g:
            _warn(stats.accel_unit_message)
        if stats.imu_gaps:
            _warn(f"{stats.imu_gaps} IMU gap(s): no sample for longer than fusion.imu_gap_limit_s "
                  "(the last input was held)")
    _evaluate(summary, dataset, out_dir, groundtruth, plot, len(lidar_traj))
    if plot and totals_ms:
        from .plots import plot_run
        plot_run(out_dir, summary.get("accuracy", {}).get("groundtruth_file"))
    (out_dir / "config.yaml").write_text(config_to_yaml(odo.effective_config))
    summary["voxel_size_m"] = float(odo.effective_config.get("map.voxel_size_m"))
    (out_dir / "summary.json").write_text(json.dumps(summary, indent=2, default=_json_default))
    return summary


def _evaluate(summary: dict[str, Any], dataset: Dataset, out_dir: Path, groundtruth: Path | None, plot: bool,
              poses: int) -> None:
    from .evaluation import evaluate_files
    if poses < 3:
        return
    gt_scans = groundtruth
    if gt_scans is None and (Path(dataset.path) / "groundtruth_scans.tum").exists():
        gt_scans = Path(dataset.path) / "groundtruth_scans.tum"
    if gt_scans is None:
        gt_scans = dataset.groundtruth()  # a dense ground truth (MulRan): interpolated at the scan stamps
    if gt_scans is not None:
        summary["accuracy"] = evaluate_files(out_dir / "scans_body.tum", Path(gt_scans), out_dir / "eval_scans",
                                             plot=plot)
    gt_dense = groundtruth or dataset.groundtruth()
    if gt_dense is not None and (out_dir / "odometry_body.tum").exists():
        summary["accuracy_odometry"] = evaluate_files(out_dir / "odometry_body.tum", Path(gt_dense),
                                                      out_dir / "eval_odometry", plot=plot)


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
    lines = [f"{s['mode']}: frames {s['processed']}/{s['frames']} (skipped {s['skipped']}, dropped "
             f"{s['dropped']}), converged {converged}, {s['rate_hz']:.1f} Hz overall",
             f"latency per frame: median {lat['median']:.2f} ms, p99 {lat['p99']:.2f} ms, max {lat['max']:.2f} ms"]
    for key, label in (("accuracy", "scan poses"), ("accuracy_odometry", "100 Hz odometry")):
        if s.get(key):
            lines.append(f"{label}: {_accuracy_line(s[key])}")
    return "\n".join(lines)


def _accuracy_line(acc: dict[str, Any]) -> str:
    try:
        ape = acc["ape"]["translation_m"]["rmse"]
        kitti = acc["kitti_rpe"]
        return (f"APE {ape:.3f} m (aligned RMSE), RPE {kitti['translation_pct']:.3f} % / "
                f"{kitti['rotation_deg_per_100m']:.3f} deg/100m, coverage {100 * acc['coverage']:.1f}%")
    except (KeyError, TypeError):
        return "see eval.json"
