"""Whole-frame benchmark: farlio's scan pipeline and KISS-ICP on the same scans, in the same
process and run, one after the other per frame set. Reports per-frame latency (median, p99, max)
and, when the scans have ground truth, the accuracy of both."""

from __future__ import annotations

import sys
import time
from typing import Any

import numpy as np

import farlio
from farlio import _core

MS_PER_S = 1e3
#: generated urban and handheld sequences start at rest for 2 s: benchmark scans while moving
GENERATED_SKIP_S = 2.5


def generated_scans(profile: str, scans: int, seed: int = 1) -> tuple[list[Any], Any, Any]:
    """(scans, ground-truth LiDAR poses at the scan ends, T_imu_lidar) of a generated sequence."""
    cfg = _core.sim.default_config(profile)
    cfg.seed = seed
    period = 1.0 / cfg.lidar_rate_hz
    skip = int(round(GENERATED_SKIP_S / period))
    cfg.duration_s = (skip + scans + 1) * period
    gen = _core.sim.SequenceGenerator(cfg)
    out = [gen.scan(i) for i in range(skip, skip + scans)]
    gt_body = gen.groundtruth_scans()
    T = gen.T_imu_lidar()
    gt = farlio.Trajectory()
    ends = {s.end_stamp_ns for s in out}
    for k in range(len(gt_body)):
        stamp, pose = gt_body[k]
        if stamp in ends:
            gt.push_back(stamp, pose * T)
    return out, gt, T


def _stats(ms: list[float]) -> dict[str, float]:
    a = np.asarray(ms)
    return {
        "median": float(np.median(a)),
        "p99": float(np.percentile(a, 99)),
        "max": float(a.max()),
        "mean": float(a.mean()),
    }


def _accuracy(traj: Any, gt: Any) -> dict[str, float] | None:
    if gt is None or len(gt) < 3:
        return None
    r = _core.eval.evaluate(traj, gt)
    return {
        "ape_m": r.ape.translation_m.rmse,
        "rpe_pct": r.kitti_rpe.translation_pct,
        "rpe_deg_per_100m": r.kitti_rpe.rotation_deg_per_100m,
    }


def run_farlio(scans: list[Any], config: Any) -> tuple[list[float], Any, str]:
    """(latency per frame in ms, trajectory, the device it ran on)."""
    pipe = _core.ScanPipeline(config)
    if pipe.device_message:
        print(f"farlio: {pipe.device_message}", file=sys.stderr)
    ms, traj = [], farlio.Trajectory()
    for s in scans:
        t0 = time.perf_counter()
        r = pipe.process(s)
        ms.append((time.perf_counter() - t0) * MS_PER_S)
        traj.push_back(r.stamp_ns, r.pose)
    return ms, traj, pipe.device


def run_kiss(scans: list[Any], threads: int) -> tuple[list[float], Any]:
    from kiss_icp.config import load_config
    from kiss_icp.kiss_icp import KissICP

    cfg = load_config(None)
    cfg.registration.max_num_threads = threads
    has_time = all(len(s.time_s) == len(s) for s in scans)
    cfg.data.deskew = has_time
    kiss = KissICP(cfg)

    # inputs converted before the clock starts: only registration is timed, as for farlio.
    # KISS-ICP's dataloaders hand it per-point times normalised to [0, 1] over the scan.
    def normalised(t: np.ndarray) -> np.ndarray:
        span = t.max() - t.min()
        return (t - t.min()) / span if span > 0 else np.zeros_like(t)

    inputs = [
        (
            np.asarray(s.points, dtype=np.float64),
            normalised(np.asarray(s.time_s, dtype=np.float64)) if has_time else np.zeros(len(s)),
        )
        for s in scans
    ]
    ms, traj = [], farlio.Trajectory()
    for s, (pts, t) in zip(scans, inputs):
        t0 = time.perf_counter()
        kiss.register_frame(pts, t)
        ms.append((time.perf_counter() - t0) * MS_PER_S)
        traj.push_back(s.end_stamp_ns, _core.SE3.from_matrix(kiss.last_pose))
    return ms, traj


def compare(
    scans: list[Any], gt: Any = None, *, threads: int = 0, with_kiss: bool = True, device: str = "auto"
) -> dict[str, Any]:
    """Runs farlio (LiDAR-only scan pipeline, on `device`) and, if installed, KISS-ICP over the same scans."""
    config = _core.Config()
    config.set("num_threads", str(threads))
    config.set("device", device)
    ms, traj, used = run_farlio(scans, config)
    result: dict[str, Any] = {
        "frames": len(scans),
        "points_per_scan": float(np.mean([len(s) for s in scans])),
        "threads": threads,
        "device": used,
        "farlio": {"latency_ms": _stats(ms), "accuracy": _accuracy(traj, gt)},
    }
    if with_kiss:
        try:
            kms, ktraj = run_kiss(scans, threads)
        except ImportError:
            result["kiss_icp"] = None
        else:
            result["kiss_icp"] = {"latency_ms": _stats(kms), "accuracy": _accuracy(ktraj, gt)}
            result["speedup_median"] = (
                result["kiss_icp"]["latency_ms"]["median"] / result["farlio"]["latency_ms"]["median"]
            )
            result["speedup_p99"] = result["kiss_icp"]["latency_ms"]["p99"] / result["farlio"]["latency_ms"]["p99"]
    return result


def format_table(name: str, r: dict[str, Any]) -> str:
    rows = [
        f"{name}: {r['frames']} frames of {r['points_per_scan']:.0f} points, threads={r['threads'] or 'all'}, "
        f"farlio on {r.get('device', 'cpu')}",
        f"{'system':10s} {'median ms':>10s} {'p99 ms':>10s} {'max ms':>10s} {'APE m':>8s} {'RPE %':>8s}",
    ]
    for key in ("farlio", "kiss_icp"):
        v = r.get(key)
        if not v:
            continue
        lat, acc = v["latency_ms"], v["accuracy"] or {}
        rows.append(
            f"{key:10s} {lat['median']:10.2f} {lat['p99']:10.2f} {lat['max']:10.2f} "
            f"{acc.get('ape_m', float('nan')):8.3f} {acc.get('rpe_pct', float('nan')):8.3f}"
        )
    if "speedup_median" in r:
        rows.append(
            f"farlio is {r['speedup_median']:.2f}x faster than KISS-ICP at the median, {r['speedup_p99']:.2f}x at p99"
        )
    return "\n".join(rows)
