"""Whole-frame benchmark: farlio's scan pipeline and KISS-ICP on the same scans, in the same
process and run, one after the other per frame set. Reports per-frame latency (median, p99, max)
and, when the scans have ground truth, the accuracy of both; for farlio also the time of each
pipeline stage with the limit its work implies on this machine (pipeline/stage_limits.hpp:
yardsticks measured in the same process), the work per frame (iterations, points) and the memory
(map, peak RSS)."""

from __future__ import annotations

import resource
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import farlio
from farlio import _core

MS_PER_S = 1e3
P99 = 99
BYTES_PER_MIB = 2**20
#: the yardsticks in GB/s and G distances/s
GIGA = 1e9
KIB_PER_MIB = 2**10
#: getrusage's ru_maxrss counts KiB on Linux, bytes on macOS
MAXRSS_UNITS_PER_MIB = BYTES_PER_MIB if sys.platform == "darwin" else KIB_PER_MIB
PERCENT = 100
#: the stages of FrameResult.timings in pipeline order: name in bench.json -> attribute (seconds)
STAGES = {
    "preprocess": "preprocess_s",
    "covariance": "covariance_s",
    "registration": "registration_s",
    "map_update": "map_update_s",
}
#: per frame, the whole frame minus its stages (the bindings, the pipeline's own bookkeeping)
OTHER = "other"
#: FrameResult counts reported as medians per frame in result["farlio"]["work"]
WORK_COUNTS = ("iterations", "source_points", "kept_points")
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
    T = gen.T_imu_lidar()
    return out, lidar_poses(gen.groundtruth_scans(), T, {s.end_stamp_ns for s in out}), T


def lidar_poses(body: Any, T_imu_lidar: Any, stamps: set[int] | None = None) -> Any:
    """Body (IMU) poses as LiDAR poses (what farlio's scan pipeline and KISS-ICP register), at every
    stamp or at those of `stamps` only."""
    out = farlio.Trajectory()
    for k in range(len(body)):
        stamp, pose = body[k]
        if stamps is None or stamp in stamps:
            out.push_back(stamp, pose * T_imu_lidar)
    return out


def _median_p99(ms: Sequence[float]) -> dict[str, float]:
    a = np.asarray(ms)
    return {"median": float(np.median(a)), "p99": float(np.percentile(a, P99))}


def _stats(ms: Sequence[float]) -> dict[str, float]:
    a = np.asarray(ms)
    return {**_median_p99(a), "max": float(a.max()), "mean": float(a.mean())}


def _accuracy(traj: Any, gt: Any) -> dict[str, float] | None:
    if gt is None or len(gt) < 3:
        return None
    r = _core.eval.evaluate(traj, gt)
    return {
        "ape_m": r.ape.translation_m.rmse,
        "rpe_pct": r.kitti_rpe.translation_pct,
        "rpe_deg_per_100m": r.kitti_rpe.rotation_deg_per_100m,
    }


@dataclass
class FarlioRun:
    """What one pass of farlio's scan pipeline over the scans measured, frame by frame."""

    device: str
    #: whole frame: perf_counter around ScanPipeline.process
    frame_ms: list[float] = field(default_factory=list)
    stage_ms: dict[str, list[float]] = field(default_factory=lambda: {s: [] for s in STAGES})
    work: dict[str, list[int]] = field(default_factory=lambda: {c: [] for c in WORK_COUNTS})
    trajectory: Any = field(default_factory=farlio.Trajectory)
    #: per stage, the limit of each frame's work (ms) at the yardsticks' rates; empty without yardsticks
    limit_ms: dict[str, list[float]] = field(default_factory=dict)
    #: the machine's rates the limits were computed at (measure_yardsticks); None without limits
    yardsticks: Any = None
    #: map bytes, voxels, points after the last frame and the process's peak RSS (memory_report)
    memory: dict[str, float] = field(default_factory=dict)

    def add(self, r: Any, ms: float, limits: Any = None) -> None:
        """Frame result `r` of ScanPipeline.process, which took `ms` in all; `limits` its
        stage limits (stage_limits, FrameTimings; None: not measured)."""
        self.frame_ms.append(ms)
        if limits is not None:
            for stage, attribute in STAGES.items():
                self.limit_ms.setdefault(stage, []).append(getattr(limits, attribute) * MS_PER_S)
        for stage, attribute in STAGES.items():
            self.stage_ms[stage].append(getattr(r.timings, attribute) * MS_PER_S)
        for count in WORK_COUNTS:
            self.work[count].append(getattr(r, count))
        self.trajectory.push_back(r.stamp_ns, r.pose)

    def pool(self, later: FarlioRun) -> None:
        """Adds the frames of a later pass over the same scans (`farlio bench --rounds`): their
        times, work and limits are pooled; the trajectory stays this pass's (the pipeline is
        deterministic for a thread count: every pass gives the same poses), the memory becomes the
        later pass's (the process's peak RSS so far)."""
        self.frame_ms += later.frame_ms
        for stage in STAGES:
            self.stage_ms[stage] += later.stage_ms[stage]
        for count in WORK_COUNTS:
            self.work[count] += later.work[count]
        for stage, ms in later.limit_ms.items():
            self.limit_ms.setdefault(stage, []).extend(ms)
        self.memory = later.memory

    def stage_sums_ms(self) -> np.ndarray:
        """Per frame, the sum of the stages (they run inside the frame: at most frame_ms)."""
        return np.sum([self.stage_ms[s] for s in STAGES], axis=0)


def memory_report(pipe: Any, last: Any) -> dict[str, float]:
    """The pipeline's map after frame result `last`, and the peak RSS of this process so far (it
    includes the scans held in memory and every run before in the same process)."""
    return {
        "map_bytes": pipe.map_memory_bytes,
        "map_voxels": last.map_voxels,
        "map_points": last.map_points,
        "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / MAXRSS_UNITS_PER_MIB,
    }


def run_farlio(scans: list[Any], config: Any, limits: bool = False, announce: bool = True) -> FarlioRun:
    """Latency, stage times and work per frame, trajectory, device and memory of farlio's run;
    with `limits`, on the CPU, also each frame's stage limits at the machine's yardsticks (the
    CPU's rates say nothing about a GPU's stages: none there). `announce`: print the pipeline's
    device message (once per data set, not per round)."""
    pipe = _core.ScanPipeline(config)
    if announce and pipe.device_message:
        print(f"farlio: {pipe.device_message}", file=sys.stderr)
    run = FarlioRun(pipe.device)
    if limits and pipe.device == "cpu":
        run.yardsticks = yardsticks(int(config.get("num_threads")))
    k = int(config.get("map.covariance_neighbors"))
    for s in scans:
        t0 = time.perf_counter()
        r = pipe.process(s)
        ms = (time.perf_counter() - t0) * MS_PER_S
        run.add(r, ms, _core.stage_limits(r, k, run.yardsticks) if run.yardsticks is not None else None)
    run.memory = memory_report(pipe, r)
    return run


def _farlio_result(run: FarlioRun, gt: Any) -> dict[str, Any]:
    latency = _stats(run.frame_ms)
    stages = {s: _median_p99(ms) for s, ms in run.stage_ms.items()}
    stages[OTHER] = _median_p99(np.asarray(run.frame_ms) - run.stage_sums_ms())
    limits = {}
    if run.limit_ms:
        # the median frame's limit per stage, and how many times it the measured median is
        limits = {
            s: {"limit_ms": float(np.median(v)), "ratio": stages[s]["median"] / float(np.median(v))}
            for s, v in run.limit_ms.items()
        }
        total = float(np.median(np.sum(list(run.limit_ms.values()), axis=0)))
        limits["whole_frame"] = {"limit_ms": total, "ratio": latency["median"] / total}
    return {
        "stage_limits": limits,
        "latency_ms": latency,
        "p99_over_median": latency["p99"] / latency["median"],
        "stages_ms": stages,
        "work": {c: float(np.median(v)) for c, v in run.work.items()},
        "memory": run.memory,
        "accuracy": _accuracy(run.trajectory, gt),
    }


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


_YARDSTICKS: dict[int, Any] = {}


def yardsticks(threads: int) -> Any:
    """The machine's rates on `threads` threads (measure_yardsticks, about 1 s), measured once per
    thread count and process."""
    if threads not in _YARDSTICKS:
        _YARDSTICKS[threads] = _core.measure_yardsticks(threads)
    return _YARDSTICKS[threads]


def compare(
    scans: list[Any],
    gt: Any = None,
    *,
    threads: int = 0,
    with_kiss: bool = True,
    device: str = "auto",
    rounds: int = 1,
) -> dict[str, Any]:
    """Runs farlio (LiDAR-only scan pipeline, on `device`) and, if installed, KISS-ICP over the
    same scans, `rounds` times in turns (farlio, KISS-ICP, farlio, ...; each pass with a new
    pipeline): the frames of all passes are pooled, so that a load on the machine that comes and
    goes during the run weighs on both systems alike."""
    config = _core.Config()
    config.set("num_threads", str(threads))
    config.set("device", device)
    run, kiss_ms, kiss_traj, ratios = None, [], None, []
    for round_index in range(rounds):
        this = run_farlio(scans, config, limits=True, announce=round_index == 0)
        if run is None:
            run = this
        else:
            run.pool(this)
        if with_kiss:
            try:
                kms, ktraj = run_kiss(scans, threads)
            except ImportError:
                with_kiss = False
                continue
            kiss_ms += kms
            if kiss_traj is None:
                kiss_traj = ktraj
            ratios.append(float(np.median(kms) / np.median(this.frame_ms)))
    sticks = run.yardsticks
    result: dict[str, Any] = {
        "frames": len(scans),
        "rounds": rounds,
        "points_per_scan": float(np.mean([len(s) for s in scans])),
        "threads": threads,
        "device": run.device,
        "yardsticks": None
        if sticks is None
        else {
            "memory_read_gb_s": sticks.memory_read_bytes_per_s / GIGA,
            "l1_distances_g_s": sticks.l1_distances_per_s / GIGA,
        },
        "farlio": _farlio_result(run, gt),
    }
    if not kiss_ms:
        result["kiss_icp"] = None
    else:
        result["kiss_icp"] = {"latency_ms": _stats(kiss_ms), "accuracy": _accuracy(kiss_traj, gt)}
        result["speedup_median"] = result["kiss_icp"]["latency_ms"]["median"] / result["farlio"]["latency_ms"]["median"]
        result["speedup_p99"] = result["kiss_icp"]["latency_ms"]["p99"] / result["farlio"]["latency_ms"]["p99"]
        #: each round's ratio of the medians: how much the machine moved them during the run
        result["speedup_median_per_round"] = ratios
    return result


def format_table(name: str, r: dict[str, Any]) -> str:
    """compare's result as text: both systems' latency and accuracy, farlio's stages, work, memory."""
    return "\n".join([_system_table(name, r), _stage_table(r), _work_line(r), _memory_line(r)])


def _system_table(name: str, r: dict[str, Any]) -> str:
    rows = [
        f"{name}: {r['frames']} frames of {r['points_per_scan']:.0f} points, threads={r['threads'] or 'all'}, "
        f"farlio on {r.get('device', 'cpu')}" + _rounds_note(r),
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
        per_round = r.get("speedup_median_per_round") or []
        spread = f" (per round {min(per_round):.2f}-{max(per_round):.2f}x)" if len(per_round) > 1 else ""
        rows.append(
            f"farlio is {r['speedup_median']:.2f}x faster than KISS-ICP at the median{spread}, "
            f"{r['speedup_p99']:.2f}x at p99"
        )
    return "\n".join(rows)


def _rounds_note(r: dict[str, Any]) -> str:
    rounds = r.get("rounds", 1)
    return f", {rounds} rounds in turns with KISS-ICP, every frame counted" if rounds > 1 else ""


def _stage_row(label: str, ms: dict[str, float], limit: dict[str, float] | None, note: str) -> str:
    lim = f"{limit['limit_ms']:10.2f} {limit['ratio']:8.1f}x" if limit else f"{'':10s} {'':9s}"
    return f"{label:14s} {ms['median']:10.2f} {ms['p99']:10.2f} {lim}   {note}"


def _stage_table(r: dict[str, Any]) -> str:
    """farlio's stages with their limit (the time their work takes at the yardsticks' rates) and
    share of the median frame, the whole frame with its p99/median, and KISS-ICP's whole frame
    with farlio's speed-up at the median and p99."""
    f = r["farlio"]
    whole, limits = f["latency_ms"], f.get("stage_limits") or {}
    rows = [f"{'stage':14s} {'median ms':>10s} {'p99 ms':>10s} {'limit ms':>10s} {'/ limit':>9s}   share"]
    for stage, ms in f["stages_ms"].items():
        note = f"{ms['median'] / whole['median'] * PERCENT:4.0f} %"
        rows.append(_stage_row(stage.replace("_", " "), ms, limits.get(stage), note))
    rows.append(_stage_row("whole frame", whole, limits.get("whole_frame"), f"p99/median {f['p99_over_median']:.2f}"))
    if "speedup_median" in r:
        note = f"farlio {r['speedup_median']:.2f}x faster at the median, {r['speedup_p99']:.2f}x at p99"
        rows.append(_stage_row("KISS-ICP frame", r["kiss_icp"]["latency_ms"], None, note))
    if limits:
        y = r["yardsticks"]
        rows.append(
            f"limit: the stage's unavoidable work at {y['memory_read_gb_s']:.1f} GB/s memory read and "
            f"{y['l1_distances_g_s']:.2f} G distances/s in L1 (measured now; docs/performance.md)"
        )
    return "\n".join(rows)


def _work_line(r: dict[str, Any]) -> str:
    w = r["farlio"]["work"]
    return (
        f"work (median per frame): {w['iterations']:.0f} iterations, {w['source_points']:,.0f} source points, "
        f"{w['kept_points']:,.0f} kept points"
    )


def _memory_line(r: dict[str, Any]) -> str:
    m = r["farlio"]["memory"]
    return (
        f"memory: map {m['map_bytes'] / BYTES_PER_MIB:.1f} MiB ({m['map_voxels']:,} voxels, {m['map_points']:,} "
        f"points), peak RSS of the process so far {m['peak_rss_mib']:.0f} MiB"
    )
