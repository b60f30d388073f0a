"""The online (threaded) odometry from Python: IMU pushed from a second Python thread, scans from
the main one, in lockstep, must give the deterministic replay's trajectory (zero latency)."""

from __future__ import annotations

import threading

import farlio
import numpy as np
from farlio import _core


def test_online_odometry_from_two_python_threads_equals_the_replay(tmp_path):
    from farlio.datasets import open_dataset
    from farlio.simulation import generate

    seq = tmp_path / "urban"
    generate("urban", seq, duration_s=2.0)
    ds = open_dataset(seq)
    scans = [ds.scan(i) for i in range(len(ds))]
    imu = ds.imu()
    T = ds.T_imu_lidar()

    options = _core.ReplayOptions()
    options.latency = _core.LatencyModel.Zero
    replay = farlio.Odometry(farlio.Config(), T, ds.gravity_m_s2(), imu, options)
    expected = [replay.process(s).body_pose.translation for s in scans]
    replay.finish(imu[-1].stamp_ns)
    expected_odometry = replay.take_odometry()

    online = farlio.OnlineOdometry(farlio.Config(), T, ds.gravity_m_s2())
    pushed_until = threading.Semaphore(0)
    scan_done = threading.Semaphore(0)

    def push_imu() -> None:
        k = 0
        for s in scans:
            while k < len(imu) and imu[k].stamp_ns <= s.end_stamp_ns:
                online.add_imu(imu[k])
                k += 1
            pushed_until.release()
            scan_done.acquire()
        while k < len(imu):
            online.add_imu(imu[k])
            k += 1

    worker = threading.Thread(target=push_imu)
    worker.start()
    for s in scans:
        pushed_until.acquire()
        assert online.add_scan(s)
        online.wait_idle()
        scan_done.release()
    worker.join()
    online.stop()

    frames = online.take_frames()
    assert online.inertial and len(frames) == len(scans) and all(f.processed and f.fused for f in frames[1:])
    got = np.array([f.body_pose.translation for f in frames])
    assert np.abs(got - np.array(expected)).max() < 1e-6
    samples = online.take_odometry()
    assert len(samples) == len(expected_odometry) > 150
    assert [s.stamp_ns for s in samples] == [t for t, _ in expected_odometry]
    assert (
        max(np.abs(s.body_pose.translation - p.translation).max() for s, (_, p) in zip(samples, expected_odometry))
        < 1e-6
    )


def test_add_scan_consume_moves_the_scan_in_with_the_same_result(tmp_path):
    """consume=True (what the ROS node does) leaves the Python scan empty and gives the frames of a
    copied scan."""
    from farlio.datasets import open_dataset
    from farlio.simulation import generate

    seq = tmp_path / "urban"
    generate("urban", seq, duration_s=0.6)
    ds = open_dataset(seq)
    poses = []
    for consume in (False, True):
        online = farlio.OnlineOdometry(farlio.Config(), ds.T_imu_lidar(), ds.gravity_m_s2())
        for i in range(len(ds)):
            scan = ds.scan(i)
            n = len(scan)
            assert online.add_scan(scan, consume=consume)
            assert len(scan) == (0 if consume else n)
            assert len(scan.time_s) == (0 if consume else n)
            online.wait_idle()
        online.stop()
        frames = online.take_frames()
        assert len(frames) == len(ds) and all(f.processed for f in frames)
        poses.append(np.array([f.body_pose.matrix() for f in frames]))
    np.testing.assert_array_equal(poses[0], poses[1])
