"""The bound classes fed straight from Python, without a reader in between: points with NaN times
are dropped as the readers drop them, and calls from several threads at once are serialised (each
class's thread-safety is documented in docs/hardening.md)."""

from __future__ import annotations

import math
import threading

import farlio
import numpy as np
import pytest
from farlio import _core
from farlio.runner import replay_options
from farlio.simulation import make_config

SCANS = 6


@pytest.fixture(scope="module")
def urban():
    """The first scans of a short generated urban drive (every 4th point), its IMU and extrinsic."""
    gen = _core.sim.SequenceGenerator(make_config("urban", duration_s=SCANS / 10.0 + 0.05))
    scans = []
    for i in range(SCANS):
        s = gen.scan(i)
        scans.append(with_times(s, np.asarray(s.time_s), step=4))
    return scans, gen.imu(), gen.T_imu_lidar()


def with_times(scan, times, step: int = 1):
    """Every step-th point of `scan` with the given per-point times."""
    points = np.ascontiguousarray(np.asarray(scan.points)[::step], dtype=np.float32)
    times = np.ascontiguousarray(np.asarray(times)[::step], dtype=np.float32)
    return farlio.Scan(points, times, start_stamp_ns=scan.start_stamp_ns, end_stamp_ns=scan.end_stamp_ns)


def with_nan_times(scan, every: int = 50):
    """The scan with every `every`-th point's time NaN; and how many those are."""
    times = np.asarray(scan.time_s).copy()
    times[::every] = np.nan
    return with_times(scan, times), len(times[::every])


def translation_gap_m(a, b) -> float:
    return float(np.linalg.norm(np.asarray((a.inverse() * b).translation)))


def test_nan_point_times_are_dropped_by_every_entry_point(urban):
    scans, imu, T = urban
    config = _core.Config()
    config.set("registration.time_budget_factor", "1000")
    pipe, clean_pipe = _core.ScanPipeline(config), _core.ScanPipeline(config)
    odo = _core.Odometry(config, T, 9.81, imu, replay_options("fixed", 0.02))
    online = _core.OnlineOdometry(config, T, 9.81)
    for s in imu:
        online.add_imu(s)
    for scan in scans:
        bad, count = with_nan_times(scan)
        clean = with_times(bad, np.asarray(bad.time_s))
        assert clean.remove_non_finite() == count
        r, c = pipe.process(bad), clean_pipe.process(clean)
        assert r.non_finite_points == count
        assert translation_gap_m(r.pose, c.pose) < 1e-9
        fr = odo.process(bad)
        assert fr.processed and fr.scan.non_finite_points == count
        assert online.add_scan(bad)
        online.wait_idle()
    frames = online.take_frames()
    assert len(frames) == SCANS
    assert all(f.processed and f.scan.non_finite_points > 0 for f in frames)
    assert all(math.isfinite(f.body_pose.translation[0]) for f in frames)


@pytest.mark.parametrize("kind", ["ScanPipeline", "Odometry"])
def test_calls_from_several_threads_are_serialised(urban, kind):
    """Four threads call process() on one object at once (the GIL released inside); each call runs
    alone, so every frame is processed and its pose finite, and the frame count adds up."""
    scans, imu, T = urban
    config = _core.Config()
    obj = _core.ScanPipeline(config) if kind == "ScanPipeline" else _core.Odometry(config, T, 9.81, imu)
    results, errors = [], []

    def worker(k: int) -> None:
        try:
            for scan in scans[k::4]:
                r = obj.process(scan)
                results.append(r if kind == "ScanPipeline" else r.scan)
                if kind == "Odometry":
                    obj.take_odometry()
                else:
                    obj.map_points()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert len(results) == SCANS
    assert all(math.isfinite(float(np.asarray(r.pose.translation)[0])) for r in results)
    if kind == "ScanPipeline":
        assert obj.frames == SCANS


def test_a_staged_next_scan_changes_no_result(urban):
    """Offline loops may hand the pipeline the scan after the one about to be processed
    (ScanPipeline.stage_next; on the GPU it is uploaded while the frame runs): the same bits as
    without, on whichever device runs. The pipeline holds the scans staged last, so that one handed
    over as a temporary is safe; a scan never processed is simply dropped."""
    scans, _, _ = urban
    config = _core.Config()
    config.set("registration.time_budget_factor", "1000")
    plain, staged = _core.ScanPipeline(config), _core.ScanPipeline(config)
    staged.stage_next(with_times(scans[0], np.asarray(scans[0].time_s)))  # a temporary, never processed
    for i, scan in enumerate(scans):
        if i + 1 < len(scans):
            staged.stage_next(scans[i + 1])
        a, b = plain.process(scan), staged.process(scan)
        assert np.array_equal(a.pose.matrix(), b.pose.matrix())
        assert a.kept_points == b.kept_points and a.source_points == b.source_points
    assert staged.frames == plain.frames == len(scans)
