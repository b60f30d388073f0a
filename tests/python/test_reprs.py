"""Bound objects print their values: repr() names the type and shows the numbers, never
'<... object at 0x...>'."""

from __future__ import annotations

import math

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")

from farlio.datasets import open_dataset  # noqa: E402
from farlio.simulation import generate  # noqa: E402

SIM_DURATION_S = 0.6
FRAMES = 4
YAW_DEG = 90.0
TRANSLATION = (1.5, -2.25, 3.0)


def check(obj, *values: str) -> str:
    """repr(obj) names its type, holds every one of `values` and no address."""
    text = repr(obj)
    assert "object at 0x" not in text, text
    assert text.startswith(type(obj).__name__ + "("), text
    for v in values:
        assert v in text, (v, text)
    return text


def pose(translation=TRANSLATION, yaw_deg=YAW_DEG):
    m = np.eye(4)
    c, s = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    m[:2, :2] = [[c, -s], [s, c]]
    m[:3, 3] = translation
    return core.SE3.from_matrix(m)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    path = tmp_path_factory.mktemp("seq") / "urban"
    generate("urban", path, duration_s=SIM_DURATION_S)
    return open_dataset(path)


def test_se3_shows_translation_and_rotation():
    assert check(pose(), "SE3(") == "SE3(t=[1.5, -2.25, 3], rpy_deg=[0, 0, 90])"


def test_scan_trajectory_imu_calibration():
    points = np.zeros((5, 3), dtype=np.float32)
    scan = core.Scan(points, time_s=np.zeros(5, np.float32), start_stamp_ns=1_000, end_stamp_ns=100_001_000)
    text = check(scan, "5 points", "duration_s=0.1", "start_stamp_ns=1000", "end_stamp_ns=100001000", "'time_s'")
    assert "intensity" not in text and "sensor_id" not in text
    traj = core.Trajectory()
    check(traj, "0 poses")
    traj.push_back(7, core.SE3())
    traj.push_back(9, pose())
    check(traj, "2 poses", "first_stamp_ns=7", "last_stamp_ns=9", "t=[1.5, -2.25, 3]")
    check(core.ImuSample(42, np.array([0.5, 0, 0]), np.array([0, 0, 9.81])), "stamp_ns=42", "[0.5, 0, 0]", "9.81")
    calib = core.io.Calibration()
    check(calib, "gravity_m_s2=None", "T_imu_lidar=SE3(")
    calib.T_imu_lidar_by_name = {"/front": pose()}
    calib.gravity_m_s2 = 9.8
    check(calib, "T_imu_lidar_by_name={'/front': SE3(t=[1.5, -2.25, 3]", "gravity_m_s2=9.8")


def test_evaluation_results():
    est, gt = core.Trajectory(), core.Trajectory()
    for k in range(10):
        gt.push_back(k * 100_000_000, pose((k * 1.0, 0.0, 0.0), 0.0))
        est.push_back(k * 100_000_000, pose((k * 1.0, 0.25, 0.0), 0.0))
    r = core.eval.evaluate(est, gt)
    check(r, "associated_poses=10", "coverage=1")
    check(r.ape, "ErrorStats(count=10", "Alignment(")
    check(r.ape.translation_raw_m, "rmse=0.25")
    check(r.ape.alignment, "scale=1", "rank_deficient=True")
    check(r.kitti_rpe, "segment_count=")
    check(r.rpe, "translation_m=ErrorStats(count=9")


def test_pipeline_and_odometry_results(dataset):
    scans = [dataset.scan(i) for i in range(FRAMES)]
    pipe = core.ScanPipeline(core.Config())
    frame = [pipe.process(s) for s in scans][-1]
    check(frame, f"stamp_ns={frame.stamp_ns}", f"input_points={frame.input_points}", "pose=SE3(")
    check(frame.timings, "total_s=", "device_timed=False")
    check(core.register_pair(scans[1], scans[0]), "iterations=", "converged=")

    options = core.ReplayOptions()
    options.latency = core.LatencyModel.Zero
    odo = core.Odometry(core.Config(), dataset.T_imu_lidar(), dataset.gravity_m_s2(), dataset.imu(), options)
    result = [odo.process(s) for s in scans][-1]
    check(result, "processed=True", "scan=FrameResult(", "body_pose=SE3(")
    check(odo.fusion_stats, "lidar_groups_accepted=", "gyro_bias_rad_s=[")

    online = core.OnlineOdometry(core.Config(), dataset.T_imu_lidar(), dataset.gravity_m_s2())
    imu = dataset.imu()
    for s in scans:  # each scan after the IMU samples up to its end, as they arrive live
        for sample in (m for m in imu if m.stamp_ns <= s.end_stamp_ns):
            online.add_imu(sample)
        imu = [m for m in imu if m.stamp_ns > s.end_stamp_ns]
        online.add_scan(s)
        online.wait_idle()
    for sample in imu:
        online.add_imu(sample)
    online.stop()
    samples = online.take_odometry()
    assert samples
    check(samples[-1], f"stamp_ns={samples[-1].stamp_ns}", "velocity_body_m_s=[")
