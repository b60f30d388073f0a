"""The real recordings in ../shared/data/real through `farlio run` and the dataloaders: Ouster pcaps
(+ json) and the Ouster ROS 1 packet bag with their IMU packets, the Ouster OSF file, and the 16
KITTI scans. Skipped
without ../shared/data (or without ouster-sdk for the Ouster files)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("farlio._core")

from farlio.cli import main  # noqa: E402
from farlio.datasets import detect_format, open_dataset  # noqa: E402

OS1_PCAP = "OS-1-128_v2.3.0_1024x10_lb_n3.pcap"
OS1_POSES = "OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt"
OS1_SCANS, OS1_IMU_SAMPLES = 3, 30
OUSTER_BAG = "512x10_raw.bag"
BAG_IMU_SAMPLES = 10
SINGLE_SCAN_PCAPS = ["OS-0-128-U1_v2.3.0_1024x10.pcap", "OS-2-128-U1_v2.3.0_1024x10.pcap"]
SCAN_PERIOD_S = 0.1
GRAVITY_M_S2 = 9.81
#: a stationary-ish handheld/vehicle IMU reads |a| ~ g within this
ACCEL_NORM_TOLERANCE = 1.5
#: Ouster's own estimate is not ground truth, and 3 scans leave no time for the velocity to settle:
#: position within this of it, heading within ANGLE_TOLERANCE_DEG
OUSTER_POSE_TOLERANCE_M = 0.2
ANGLE_TOLERANCE_DEG = 1.0
KITTI_SCANS = 16
OSF_FILE, OSF_SCANS = "osf_fw_3.2_10scans.osf", 10
#: a vehicle at ~8 m/s: every step between scans within this factor of the median step, and
#: consecutive steps in nearly the same direction (6k-point scans: the first ones vary by ~30%)
STEP_RATIO_LIMIT = 1.5
MIN_STEP_COSINE = 0.95
#: a car: under 40 m/s, so under 4 m between 10 Hz scans
MAX_STEP_M = 4.0


@pytest.fixture
def ouster_dir(shared_data) -> Path:
    pytest.importorskip("ouster.sdk")
    return shared_data / "real" / "ouster"


def run_cli(path: Path, out: Path, *extra: str) -> dict:
    assert main(["run", str(path), "--out", str(out), "--no-progress", *extra]) == 0
    return json.loads((out / "summary.json").read_text())


def kitti_poses(path: Path) -> np.ndarray:
    rows = np.loadtxt(path, ndmin=2)
    out = np.tile(np.eye(4), (len(rows), 1, 1))
    out[:, :3, :] = rows.reshape(-1, 3, 4)
    return out


def test_ouster_pcap_follows_ouster_estimate(ouster_dir, tmp_path):
    pcap = ouster_dir / OS1_PCAP
    assert detect_format(pcap) == "ouster"
    ds = open_dataset(pcap)
    assert len(ds) == OS1_SCANS and len(ds.imu()) == OS1_IMU_SAMPLES
    scan = ds.scan(1)
    t = np.asarray(scan.time_s)
    assert 0.0 <= t.min() and t.max() <= SCAN_PERIOD_S
    assert (scan.end_stamp_ns - scan.start_stamp_ns) / 1e9 == pytest.approx(SCAN_PERIOD_S, rel=0.01)
    accel = np.array([s.accel_m_s2 for s in ds.imu()])
    assert np.linalg.norm(accel, axis=1).mean() == pytest.approx(GRAVITY_M_S2, abs=ACCEL_NORM_TOLERANCE)
    summary = run_cli(pcap, tmp_path / "run")
    assert summary["processed"] == OS1_SCANS and summary["mode"] == "lidar-inertial"
    ours = kitti_poses(tmp_path / "run" / "scans_lidar_kitti.txt")
    theirs = kitti_poses(ouster_dir / OS1_POSES)
    assert np.abs(ours[:, :3, 3] - theirs[:, :3, 3]).max() < OUSTER_POSE_TOLERANCE_M
    for a, b in zip(ours, theirs):
        cos = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1.0) / 2.0
        assert np.degrees(np.arccos(np.clip(cos, -1, 1))) < ANGLE_TOLERANCE_DEG
    for png in ("trajectory.png", "latency.png"):
        assert (tmp_path / "run" / png).stat().st_size > 0


def test_ouster_packet_bag(ouster_dir, tmp_path):
    bag = ouster_dir / OUSTER_BAG
    assert detect_format(bag) == "ouster"
    ds = open_dataset(bag)
    assert len(ds) == 1 and len(ds.imu()) == BAG_IMU_SAMPLES
    stamps = [s.stamp_ns for s in ds.imu()]
    scan = ds.scan(0)
    # IMU packets and columns share the sensor clock: the samples lie within the scan's 0.1 s
    assert scan.start_stamp_ns <= stamps[0] and stamps[-1] <= scan.end_stamp_ns + SCAN_PERIOD_S * 1e9
    assert len(scan) > 0 and np.all(np.isfinite(scan.points))
    summary = run_cli(bag, tmp_path / "run")
    assert summary["processed"] == 1


@pytest.mark.parametrize("name", SINGLE_SCAN_PCAPS)
def test_single_scan_pcaps(ouster_dir, name):
    ds = open_dataset(ouster_dir / name)
    assert len(ds) == 1 and len(ds.imu()) == BAG_IMU_SAMPLES
    pts = np.asarray(ds.scan(0).points)
    assert len(pts) > 10_000 and np.linalg.norm(pts, axis=1).min() > 0.0


def test_missing_ouster_metadata_is_named(ouster_dir, tmp_path):
    lone = tmp_path / "capture.pcap"
    lone.write_bytes((ouster_dir / OS1_PCAP).read_bytes()[:4096])
    with pytest.raises(ValueError, match=r"capture\.pcap: no sensor metadata: expected capture\.json"):
        open_dataset(lone)


def test_kitti_scans_give_a_sane_trajectory(shared_data, tmp_path):
    scans = shared_data / "real" / "kitti_16_scans"
    summary = run_cli(scans, tmp_path / "run")
    assert summary["processed"] == KITTI_SCANS and summary["converged_fraction"] == 1.0
    poses = np.loadtxt(tmp_path / "run" / "scans_lidar.tum")
    steps = np.linalg.norm(np.diff(poses[:, 1:4], axis=0), axis=1)
    assert np.all(steps < MAX_STEP_M)
    # a car drives forward (LiDAR x) and stays on the ground plane
    travel = poses[-1, 1:4] - poses[0, 1:4]
    assert travel[0] > 0.5 * np.linalg.norm(travel) and abs(travel[2]) < 0.1 * np.linalg.norm(travel) + 0.5


# The paper's weighting of point-to-point factors (Omega = I): sigma = sqrt(map.covariance_epsilon)
PAPER_P2P_SIGMA = "registration.point_to_point_sigma_m=0.0316"


@pytest.mark.parametrize("paper_weighting", [False, True])
def test_ouster_osf_gives_a_steady_trajectory(ouster_dir, tmp_path, paper_weighting):
    # 10 sparse scans (about 6k points), a flying start and no IMU, no ground truth. Measured:
    # with the paper's point-to-point weighting the steps are 0.65-1.1 m in a steady direction;
    # with farlio's default (sigma = half the map spacing, which fixes the racetrack launch,
    # docs/odometry.md) the steps shrink to 0.05-0.53 m and the direction reverses between scans:
    # a known limitation on sparse clouds without IMU, for which docs/odometry.md recommends the
    # paper's weighting. The default run is only checked to complete with bounded steps.
    osf = ouster_dir / OSF_FILE
    assert detect_format(osf) == "ouster"
    summary = run_cli(osf, tmp_path / "run", *(["--set", PAPER_P2P_SIGMA] if paper_weighting else []))
    assert summary["processed"] == OSF_SCANS and summary["converged_fraction"] == 1.0
    poses = np.loadtxt(tmp_path / "run" / "scans_lidar.tum")
    steps = np.diff(poses[:, 1:4], axis=0)
    assert np.all(np.linalg.norm(steps, axis=1) < MAX_STEP_M)
    lengths = np.linalg.norm(steps, axis=1)
    if paper_weighting:
        cosines = np.sum(steps[1:] * steps[:-1], axis=1) / (lengths[1:] * lengths[:-1])
        assert np.all(cosines > MIN_STEP_COSINE)
        ratio = lengths / np.median(lengths)
        assert np.all(ratio < STEP_RATIO_LIMIT) and np.all(ratio > 1.0 / STEP_RATIO_LIMIT)


def test_kitti_scans_started_in_motion_with_an_imu_from_their_trajectory(shared_data, tmp_path):
    """The real KITTI scans begin with the car at ~8 m/s. With an IMU synthesised from their own
    LiDAR-only trajectory (a cubic fit of position and rotation, gravity along the first scan's -z),
    the LIO initialises in motion within 1 s of the first scan, from the real scans' registration
    noise, and its scan poses stay on the LiDAR-only ones."""
    from farlio import _core
    from farlio.runner import replay_options

    ds = open_dataset(shared_data / "real" / "kitti_16_scans")
    scans = [ds.scan(i) for i in range(len(ds))]
    lidar_only = _core.Config()
    lidar_only.set("fusion.enabled", "false")
    odo = _core.Odometry(lidar_only, _core.SE3(), GRAVITY_M_S2, [], replay_options("fixed", 0.02))
    poses = [odo.process(s).body_pose for s in scans]
    t0 = scans[0].end_stamp_ns
    t = np.array([(s.end_stamp_ns - t0) / 1e9 for s in scans])
    position = np.polynomial.polynomial.Polynomial
    fits = [position.fit(t, [p.translation[i] for p in poses], 3) for i in range(3)]
    rotvec = [np.asarray((poses[0].inverse() * p).log())[3:] for p in poses]
    turn = [position.fit(t, [r[i] for r in rotvec], 3) for i in range(3)]
    imu = []
    for k in range(int(round((t[-1] + 0.2) * 100)) + 1):
        tk = -0.1 + k / 100.0
        R = np.asarray(poses[0].rotation()) @ np.asarray(
            _core.SE3.exp(np.r_[np.zeros(3), [f(tk) for f in turn]]).rotation()
        )
        accel_world = np.array([f.deriv(2)(tk) for f in fits])
        specific_force = R.T @ (accel_world + np.array([0.0, 0.0, GRAVITY_M_S2]))
        rate = np.array([f.deriv(1)(tk) for f in turn])  # small rotations: the body rate
        imu.append(_core.ImuSample(t0 + round(tk * 1e9), rate, specific_force))
    lio = _core.Odometry(_core.Config(), _core.SE3(), GRAVITY_M_S2, imu, replay_options("fixed", 0.02))
    fused = [lio.process(s).body_pose for s in scans]
    stats = lio.fusion_stats
    init = stats.initialization
    assert init.mode == "in motion" and (init.stamp_ns - t0) / 1e9 <= 1.0, init
    speed = np.linalg.norm([f.deriv(1)((init.stamp_ns - t0) / 1e9) for f in fits])
    assert speed > 5.0 and abs(init.speed_m_s - speed) < 0.5, (init, speed)
    assert stats.reinitializations == 0
    # relative to the first scan: the LIO's map frame is levelled by the first samples, whose specific
    # force the car's acceleration tilts (summary.json world_tilt_deg), LiDAR-only's is the first scan's
    gaps = [
        np.linalg.norm(
            np.asarray((fused[0].inverse() * a).translation) - np.asarray((poses[0].inverse() * b).translation)
        )
        for a, b in zip(fused, poses)
    ]
    print(f"initialised at {init.speed_m_s:.2f} m/s (fit {speed:.2f}); fused vs LiDAR-only at most {max(gaps):.4f} m")
    assert max(gaps) < 0.05, gaps
