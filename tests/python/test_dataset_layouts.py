"""KITTI raw and MulRan layouts written from a short generated sequence: the dataloaders read back
exactly what was written (scans, stamps, OXTS IMU, calibration, ground truth) and give the same
trajectory as the sequence folder read without per-point times (neither layout has them)."""

from __future__ import annotations

import json
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")

import farlio  # noqa: E402
from farlio._core import NS_PER_S  # noqa: E402
from farlio.datasets import detect_format, open_dataset  # noqa: E402
from farlio.datasets.folders import DEFAULT_PERIOD_NS  # noqa: E402
from farlio.datasets.kitti_raw import EARTH_RADIUS_M, OXTS_COLUMNS, parse_kitti_stamp  # noqa: E402
from farlio.evaluation import evaluate_files  # noqa: E402
from farlio.runner import replay_options, run_dataset  # noqa: E402
from farlio.simulation import make_config, write_sequence  # noqa: E402

SIM_DURATION_S = 1.5
SIM_SEED = 4
POSE_TOLERANCE_M = 1e-3
#: a fixed result latency makes the replay deterministic (the measured one varies with the load)
FIXED_LATENCY_S = 0.01
DETERMINISTIC = replay_options("fixed", FIXED_LATENCY_S)
OXTS_ACCEL, OXTS_GYRO = 11, 17  # first column of ax ay az and of wx wy wz
#: where the generated drive is put on the Earth (Karlsruhe), and its altitude
ORIGIN_LAT_DEG, ORIGIN_LON_DEG, ORIGIN_ALT_M = 49.0, 8.4, 110.0
#: OXTS positions go through degrees of latitude/longitude and back
OXTS_POSE_TOLERANCE_M = 1e-6
#: the KITTI-layout run: long enough to move (urban stands still for its first ~2 s); its APE
#: against the KITTI ground truth, and the APE of the same poses one frame late
KITTI_SIM_DURATION_S = 5.0
KITTI_APE_MAX_M = 0.015
KITTI_ROTATION_MAX_DEG = 1.0
KITTI_LATE_APE_MIN_M = 0.03


class WithoutTimes:
    """A dataset whose scans lose their per-point times; imu=False also drops the IMU and the
    extrinsic (LiDAR-only in the LiDAR frame, as MulRan without --calib)."""

    def __init__(self, inner, imu: bool = True):
        self.inner, self.use_imu = inner, imu
        self.path, self.name = inner.path, inner.name

    def __len__(self):
        return len(self.inner)

    def scan(self, i):
        s = self.inner.scan(i)
        return farlio.Scan(
            np.asarray(s.points),
            intensity=np.asarray(s.intensity),
            start_stamp_ns=s.start_stamp_ns,
            end_stamp_ns=s.end_stamp_ns,
        )

    def __getattr__(self, name):
        if name == "imu" and not self.use_imu:
            return lambda: []
        if name == "T_imu_lidar" and not self.use_imu:
            return farlio.SE3
        return getattr(self.inner, name)


@pytest.fixture(scope="module")
def sequence(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("sim") / "urban"
    write_sequence(make_config("urban", duration_s=SIM_DURATION_S, seed=SIM_SEED), path)
    return path


def kitti_stamp(ns: int) -> str:
    t = datetime.fromtimestamp(ns // NS_PER_S, tz=timezone.utc)
    return f"{t:%Y-%m-%d %H:%M:%S}.{ns % NS_PER_S:09d}"


def write_kitti_raw(folder, date_dir: Path) -> Path:
    drive = date_dir / "2011_09_26_drive_0001_sync"
    (drive / "velodyne_points" / "data").mkdir(parents=True)
    (drive / "oxts" / "data").mkdir(parents=True)
    starts, ends = [], []
    for i in range(len(folder)):
        s = folder.scan(i)
        core.io.write_kitti_bin(str(drive / "velodyne_points" / "data" / f"{i:010d}.bin"), s)
        starts.append(kitti_stamp(s.start_stamp_ns))
        ends.append(kitti_stamp(s.end_stamp_ns))
    (drive / "velodyne_points" / "timestamps_start.txt").write_text("\n".join(starts) + "\n")
    (drive / "velodyne_points" / "timestamps_end.txt").write_text("\n".join(ends) + "\n")
    stamps = []
    truth = core.io.read_tum(folder.path / "groundtruth.tum")
    first = truth.interpolate_at(folder.imu()[0].stamp_ns).matrix()
    scale = np.cos(np.radians(ORIGIN_LAT_DEG))
    x0 = scale * np.radians(ORIGIN_LON_DEG) * EARTH_RADIUS_M
    y0 = scale * EARTH_RADIUS_M * np.log(np.tan(np.radians(90.0 + ORIGIN_LAT_DEG) / 2.0))
    for k, sample in enumerate(folder.imu()):
        row = np.zeros(OXTS_COLUMNS)
        w = truth.interpolate_at(sample.stamp_ns).matrix()
        x, y = x0 + w[0, 3] - first[0, 3], y0 + w[1, 3] - first[1, 3]
        row[0] = np.degrees(2.0 * np.arctan(np.exp(y / (scale * EARTH_RADIUS_M)))) - 90.0
        row[1] = np.degrees(x / (scale * EARTH_RADIUS_M))
        row[2] = ORIGIN_ALT_M + w[2, 3] - first[2, 3]
        row[3:6] = [np.arctan2(w[2, 1], w[2, 2]), -np.arcsin(w[2, 0]), np.arctan2(w[1, 0], w[0, 0])]
        row[OXTS_ACCEL : OXTS_ACCEL + 3] = sample.accel_m_s2
        row[OXTS_GYRO : OXTS_GYRO + 3] = sample.gyro_rad_s
        (drive / "oxts" / "data" / f"{k:010d}.txt").write_text(" ".join(repr(float(v)) for v in row) + "\n")
        stamps.append(kitti_stamp(sample.stamp_ns))
    (drive / "oxts" / "timestamps.txt").write_text("\n".join(stamps) + "\n")
    m = folder.T_imu_lidar().inverse().matrix()  # calib_imu_to_velo maps IMU points into the Velodyne frame
    (date_dir / "calib_imu_to_velo.txt").write_text(
        "calib_time: 25-May-2012 12:00:00\nR: "
        + " ".join(repr(float(v)) for v in m[:3, :3].ravel())
        + "\nT: "
        + " ".join(repr(float(v)) for v in m[:3, 3])
        + "\n"
    )
    return drive


def test_kitti_stamp_parsing():
    assert parse_kitti_stamp("2011-09-26 13:02:25.964389445", "x") == 1317042145964389445
    with pytest.raises(ValueError, match=r"f\.txt:3: '26/09/2011' is not a KITTI timestamp"):
        parse_kitti_stamp("26/09/2011", "f.txt:3")


def test_kitti_raw_reads_back_and_matches_the_folder(sequence, tmp_path):
    folder = open_dataset(sequence)
    drive = write_kitti_raw(folder, tmp_path / "2011_09_26")
    assert detect_format(drive) == "kitti-raw"
    ds = open_dataset(drive)
    imu, ref_imu = ds.imu(), folder.imu()
    assert [s.stamp_ns for s in imu] == [s.stamp_ns for s in ref_imu]
    np.testing.assert_array_equal([s.accel_m_s2 for s in imu], [s.accel_m_s2 for s in ref_imu])
    np.testing.assert_array_equal([s.gyro_rad_s for s in imu], [s.gyro_rad_s for s in ref_imu])
    np.testing.assert_allclose(ds.T_imu_lidar().matrix(), folder.T_imu_lidar().matrix(), atol=1e-12)
    a, b = folder.scan(2), ds.scan(2)
    assert (a.start_stamp_ns, a.end_stamp_ns) == (b.start_stamp_ns, b.end_stamp_ns)
    np.testing.assert_array_equal(a.points, b.points)
    assert any("not undistorted" in w for w in ds.warnings())
    # ground truth from the OXTS poses: the generated body poses relative to the first sample
    truth = core.io.read_tum(sequence / "groundtruth.tum")
    oxts_gt = core.io.read_tum(ds.groundtruth())
    first_inv = truth.interpolate_at(ref_imu[0].stamp_ns).inverse()
    for k in range(0, len(oxts_gt), 10):
        stamp, pose = oxts_gt[k]
        expected = (first_inv * truth.interpolate_at(stamp)).matrix()
        np.testing.assert_allclose(pose.matrix(), expected, atol=OXTS_POSE_TOLERANCE_M)
    run_dataset(WithoutTimes(folder), tmp_path / "ref", progress=False, plot=False, options=DETERMINISTIC)
    summary = run_dataset(ds, tmp_path / "raw", progress=False, plot=False, options=DETERMINISTIC)
    assert summary["accuracy"]["associated_poses"] == len(folder)  # evaluated against the OXTS poses
    ref, got = (np.loadtxt(tmp_path / d / "scans_body.tum") for d in ("ref", "raw"))
    np.testing.assert_array_equal(ref[:, 0], got[:, 0])
    assert np.abs(ref[:, 1:4] - got[:, 1:4]).max() < POSE_TOLERANCE_M


def write_mulran(folder, gt_tum: Path, root: Path) -> Path:
    (root / "sensor_data" / "Ouster").mkdir(parents=True)
    lines = []
    for i in range(len(folder)):
        s = folder.scan(i)
        core.io.write_kitti_bin(str(root / "sensor_data" / "Ouster" / f"{s.end_stamp_ns}.bin"), s)
        lines += [f"{s.end_stamp_ns},ouster", f"{s.end_stamp_ns + 1},gps"]
    (root / "sensor_data" / "data_stamp.csv").write_text("\n".join(lines) + "\n")
    gt = core.io.read_tum(gt_tum)
    rows = []
    for k in range(len(gt)):
        stamp, pose = gt[k]
        rows.append(",".join([str(stamp)] + [repr(float(v)) for v in pose.matrix()[:3, :].ravel()]))
    (root / "global_pose.csv").write_text("\n".join(rows) + "\n")
    return root


def test_mulran_reads_back_and_matches_the_folder(sequence, tmp_path):
    folder = open_dataset(sequence)
    root = write_mulran(folder, sequence / "groundtruth_scans.tum", tmp_path / "KAIST01")
    assert detect_format(root) == "mulran"
    ds = open_dataset(root)
    assert len(ds) == len(folder) and ds.imu() == []
    gt_back = core.io.read_tum(ds.groundtruth())
    gt = core.io.read_tum(sequence / "groundtruth_scans.tum")
    np.testing.assert_array_equal(gt_back.stamps_ns, gt.stamps_ns)
    np.testing.assert_allclose(gt_back.matrices(), gt.matrices(), atol=1e-9)
    run_dataset(WithoutTimes(folder, imu=False), tmp_path / "ref", progress=False, plot=False, options=DETERMINISTIC)
    run_dataset(ds, tmp_path / "mulran", progress=False, plot=False, options=DETERMINISTIC)
    ref, got = (np.loadtxt(tmp_path / d / "scans_lidar.tum") for d in ("ref", "mulran"))
    np.testing.assert_array_equal(ref[:, 0], got[:, 0])
    assert np.abs(ref[:, 1:4] - got[:, 1:4]).max() < POSE_TOLERANCE_M
    summary = json.loads((tmp_path / "mulran" / "summary.json").read_text())
    assert summary["accuracy"]["associated_poses"] == len(folder)  # global_pose.csv used as ground truth


def test_mulran_missing_scan_files_are_reported(sequence, tmp_path):
    folder = open_dataset(sequence)
    root = write_mulran(folder, sequence / "groundtruth_scans.tum", tmp_path / "KAIST02")
    victim = sorted((root / "sensor_data" / "Ouster").iterdir())[3]
    victim.unlink()
    ds = open_dataset(root)
    assert len(ds) == len(folder) - 1
    assert any("1 Ouster stamps without a file" in w and victim.stem in w for w in ds.warnings())


def test_kitti_odometry_times_convert_exactly(tmp_path):
    """times.txt seconds become exact integer ns, also for Unix times that a float64 cannot hold to
    the nanosecond; scan k is stamped times.txt[k], start and end (a motion-compensated instant)."""
    times_s = ["1700000000.123456789", "1700000000.223456791"]
    (tmp_path / "velodyne").mkdir()
    for k in range(len(times_s)):
        core.io.write_kitti_bin(str(tmp_path / "velodyne" / f"{k:06d}.bin"), farlio.Scan(np.ones((4, 3), np.float32)))
    (tmp_path / "times.txt").write_text("\n".join(times_s) + "\n")
    ds = open_dataset(tmp_path, "kitti")
    expected = [int(t.replace(".", "")) for t in times_s]
    assert [ds.scan(k).end_stamp_ns for k in range(len(times_s))] == expected
    assert [ds.scan(k).start_stamp_ns for k in range(len(times_s))] == expected
    assert ds.groundtruth() is None


def test_kitti_layout_is_stamped_at_times_txt_and_evaluates_against_its_ground_truth(tmp_path):
    """`farlio simulate --kitti` (velodyne/ motion-compensated to the scan end, times.txt,
    groundtruth_kitti.txt) run as KITTI odometry: the scan poses carry the times.txt stamps and
    match the KITTI ground truth by timestamp to cm level; one frame late they would not."""
    seq = tmp_path / "urban"
    write_sequence(make_config("urban", duration_s=KITTI_SIM_DURATION_S, seed=SIM_SEED), seq, kitti=True)
    summary = run_dataset(
        open_dataset(seq, "kitti"), tmp_path / "run", plot=False, progress=False, options=DETERMINISTIC
    )
    times_ns = list(core.io.read_stamps(seq / "times.txt"))
    estimate = core.io.read_tum(tmp_path / "run" / "scans_lidar.tum")
    assert [estimate[k][0] for k in range(len(estimate))] == times_ns

    def ape(estimate_file: Path) -> dict:
        return evaluate_files(estimate_file, seq / "groundtruth_kitti.txt", groundtruth_times=seq / "times.txt")["ape"]

    on_time = ape(tmp_path / "run" / "scans_lidar.tum")
    assert on_time["translation_m"]["rmse"] < KITTI_APE_MAX_M
    assert on_time["rotation_deg"]["rmse"] < KITTI_ROTATION_MAX_DEG
    # `farlio run` found the same ground truth (groundtruth_kitti.txt at the times.txt stamps)
    assert summary["accuracy"]["associated_poses"] == len(times_ns)
    assert summary["accuracy"]["ape"]["translation_m"]["rmse"] == pytest.approx(on_time["translation_m"]["rmse"])

    late = farlio.Trajectory()
    for k in range(len(estimate)):
        stamp, pose = estimate[k]
        late.push_back(stamp + DEFAULT_PERIOD_NS, pose)
    core.io.write_tum(tmp_path / "late.tum", late)
    assert ape(tmp_path / "late.tum")["translation_m"]["rmse"] > KITTI_LATE_APE_MIN_M


@pytest.mark.parametrize(
    ("name", "scale", "shift", "found"),
    [
        ("ns_as_seconds", 1e9, 0.0, "their unit is not seconds"),
        ("five_periods", 5.0, 0.0, "but the scan lasts 0.1 s"),
        ("relative_to_end", 1.0, -0.1, "before the scan start"),
    ],
)
def test_point_cloud_folder_checks_per_point_times(tmp_path, name, scale, shift, found):
    """The folder path checks per-point times with the check of every loader (check_point_times):
    times in ns stored as seconds, spanning 5 scan periods, or negative are rejected naming the file."""
    rng = np.random.default_rng(7)
    stamps = [1_700_000_000_000_000_000 + k * DEFAULT_PERIOD_NS for k in range(3)]
    for k, stamp in enumerate(stamps):
        times = np.sort(rng.uniform(0.0, 0.099, 200)).astype(np.float32)
        if k == 1:
            times = (times * scale + shift).astype(np.float32)
        scan = farlio.Scan(rng.uniform(-20, 20, (200, 3)).astype(np.float32), time_s=times)
        farlio._core.io.write_pcd(tmp_path / f"{stamp}.pcd", scan)
    ds = open_dataset(tmp_path)
    assert len(ds.scan(0)) == 200 and len(ds.scan(2)) == 200
    with pytest.raises(ValueError, match=rf"{stamps[1]}\.pcd: per-point times .*{found}"):
        ds.scan(1)
