"""ROS bags written with `rosbags` from a short generated sequence: every storage (ROS 1, ROS 2
sqlite3 and MCAP) and per-point time convention (Ouster, Velodyne, Hesai, Livox, Robosense) read
back by the dataloader gives the same trajectory as the sequence folder; two LiDAR topics merge
into the original scans; bad bags, topics and fields fail with errors that name them."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("farlio._core")
pytest.importorskip("rosbags")

import farlio  # noqa: E402
from farlio.cli import main  # noqa: E402
from farlio.datasets import LoadOptions, TimeOptions, detect_format, open_dataset  # noqa: E402
from farlio.datasets.rosbag import BagError  # noqa: E402
from farlio.datasets.rosbag_write import BagWriter, write_dataset  # noqa: E402
from farlio.runner import replay_options, run_dataset  # noqa: E402
from farlio.simulation import make_config, write_sequence  # noqa: E402

SIM_DURATION_S = 2.0
SIM_SEED = 11
#: the bag path must reproduce the folder's poses to this
POSE_TOLERANCE_M = 1e-3
#: a fixed result latency makes the replay deterministic (the measured one varies with the load)
FIXED_LATENCY_S = 0.01
DETERMINISTIC = replay_options("fixed", FIXED_LATENCY_S)
#: merged scans hold the same points in another order: the voxel filter keeps other representatives
MERGED_POSE_TOLERANCE_M = 1e-2
#: the second LiDAR's scans start this much later than the first's
SECOND_LIDAR_SHIFT_NS = 30_000_000
#: bytes left unnamed at the end of every point, as drivers do for alignment
POINT_PADDING = 3


@pytest.fixture(scope="module")
def sequence(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("sim") / "urban"
    write_sequence(make_config("urban", duration_s=SIM_DURATION_S, seed=SIM_SEED), path)
    return path


@pytest.fixture(scope="module")
def reference(sequence, tmp_path_factory) -> np.ndarray:
    out = tmp_path_factory.mktemp("ref")
    run_dataset(open_dataset(sequence), out, progress=False, plot=False, options=DETERMINISTIC)
    return np.loadtxt(out / "scans_body.tum")


def run_poses(dataset, out: Path) -> np.ndarray:
    run_dataset(dataset, out, progress=False, plot=False, options=DETERMINISTIC)
    return np.loadtxt(out / "scans_body.tum")


def assert_same_trajectory(a: np.ndarray, b: np.ndarray, tolerance_m: float) -> None:
    assert a.shape == b.shape
    np.testing.assert_array_equal(a[:, 0], b[:, 0])  # the same scan end stamps
    assert np.abs(a[:, 1:4] - b[:, 1:4]).max() < tolerance_m
    # quaternions (up to sign): 1 - |<qa, qb>| ~ angle^2 / 8
    dots = np.abs(np.sum(a[:, 4:8] * b[:, 4:8], axis=1))
    assert np.all(dots > np.cos(tolerance_m / 2.0))


@pytest.mark.parametrize(
    "storage,convention",
    [("ros1", "ouster"), ("sqlite3", "velodyne"), ("mcap", "hesai"), ("mcap", "livox"), ("ros1", "robosense")],
)
def test_bag_gives_the_folder_trajectory(sequence, reference, tmp_path, storage, convention):
    folder = open_dataset(sequence)
    bag = write_dataset(
        folder, tmp_path / ("rec.bag" if storage == "ros1" else "rec"), storage, convention, padding=POINT_PADDING
    )
    assert detect_format(bag) == "rosbag"
    ds = open_dataset(bag)
    assert ds.warnings() == []
    assert len(ds) == len(folder) and len(ds.imu()) == len(folder.imu())
    np.testing.assert_allclose(ds.T_imu_lidar().matrix(), folder.T_imu_lidar().matrix(), atol=1e-9)
    a, b = folder.scan(3), ds.scan(3)
    assert (a.start_stamp_ns, a.end_stamp_ns) == (b.start_stamp_ns, b.end_stamp_ns)
    np.testing.assert_array_equal(b.points, a.points)
    np.testing.assert_allclose(b.time_s, a.time_s, atol=1e-6)  # float64 Unix seconds: ~0.2 us
    assert_same_trajectory(reference, run_poses(ds, tmp_path / "out"), POSE_TOLERANCE_M)


def test_two_lidars_merge_into_the_original_scans(sequence, reference, tmp_path):
    """Odd points go to a second LiDAR, rotated into its own frame, re-cut into messages that
    start SECOND_LIDAR_SHIFT_NS later; merging must give back the scans, hence the trajectory."""
    folder = open_dataset(sequence)
    T_imu_l1 = folder.T_imu_lidar()
    T_l1_l2 = farlio.SE3.exp(np.array([0.4, -0.2, 0.1, 0.0, 0.05, 1.2]))
    M_l2_l1 = T_l1_l2.inverse().matrix()
    scans = [folder.scan(i) for i in range(len(folder))]
    pts2, abs2 = [], []
    path = tmp_path / "two.mcap"
    with BagWriter(tmp_path / "two", "mcap") as w:
        w.tf_static(scans[0].start_stamp_ns, [("imu", "lidar1", T_imu_l1), ("lidar1", "lidar2", T_l1_l2)])
        w.imu("/imu", "imu", folder.imu())
        for s in scans:
            p, t = np.asarray(s.points), np.asarray(s.time_s)
            w.cloud("/lidar1", "lidar1", s.start_stamp_ns, s.end_stamp_ns, p[0::2], t[0::2], None)
            pts2.append((p[1::2].astype(np.float64) @ M_l2_l1[:3, :3].T + M_l2_l1[:3, 3]).astype(np.float32))
            abs2.append(s.start_stamp_ns + np.round(t[1::2].astype(np.float64) * 1e9).astype(np.int64))
        p2, a2 = np.concatenate(pts2), np.concatenate(abs2)
        starts = [s.start_stamp_ns + SECOND_LIDAR_SHIFT_NS for s in scans]
        edges = [scans[0].start_stamp_ns] + starts[1:] + [scans[-1].end_stamp_ns + SECOND_LIDAR_SHIFT_NS]
        for k in range(len(edges) - 1):
            sel = (a2 >= edges[k]) & (a2 < edges[k + 1])
            w.cloud("/lidar2", "lidar2", edges[k], edges[k + 1], p2[sel], (a2[sel] - edges[k]) / 1e9, None)
    path = next((tmp_path / "two").glob("*.mcap"))
    with pytest.raises(ValueError, match=r"2 sensor_msgs/msg/PointCloud2 topics \(/lidar1, /lidar2\).*--lidar-topic"):
        open_dataset(path)
    ds = open_dataset(path, options=LoadOptions(lidar_topics=["/lidar1", "/lidar2"]))
    merged, orig = ds.scan(5), scans[5]
    assert len(merged) == len(orig)
    assert set(np.unique(merged.sensor_id)) == {0, 1}
    # the same multiset of points (each coordinate sorted: float rounding makes a joint sort unstable)
    np.testing.assert_allclose(np.sort(merged.points, axis=0), np.sort(orig.points, axis=0), atol=1e-4)
    np.testing.assert_allclose(np.sort(merged.time_s), np.sort(orig.time_s), atol=1e-6)
    assert_same_trajectory(reference, run_poses(ds, tmp_path / "out"), MERGED_POSE_TOLERANCE_M)


def small_bag(
    path: Path, storage: str = "ros1", fields=("x", "y", "z"), times=None, topic="/points", convention: str = "ouster"
) -> Path:
    """A bag of 3 small clouds (+ a few IMU samples) whose points and fields are given."""
    rng = np.random.default_rng(0)
    with BagWriter(path, storage) as w:
        for k in range(3):
            start = 1_000_000_000 + k * 100_000_000
            pts = rng.uniform(-10, 10, (50, 3)).astype(np.float32)
            if fields == ("x", "y", "z"):
                w.cloud(topic, "lidar", start, start + 100_000_000, pts, times, None, convention)
            else:
                _raw_cloud(w, topic, start, fields)
        w.imu(
            "/imu",
            "imu",
            [farlio.ImuSample(1_000_000_000 + k * 10_000_000, np.zeros(3), np.array([0, 0, 9.81])) for k in range(3)],
        )
    return path


def _raw_cloud(w: BagWriter, topic: str, stamp: int, fields) -> None:
    ft = w._type("sensor_msgs/msg/PointField")
    msg = w._type("sensor_msgs/msg/PointCloud2")(
        header=w._header(stamp, "lidar"),
        height=1,
        width=4,
        fields=[ft(name=n, offset=4 * k, datatype=7, count=1) for k, n in enumerate(fields)],
        is_bigendian=False,
        point_step=4 * len(fields),
        row_step=16 * len(fields),
        data=np.zeros(16 * len(fields), np.uint8),
        is_dense=True,
    )
    w._write(topic, "sensor_msgs/msg/PointCloud2", stamp, msg)


def test_missing_and_wrong_topics_are_named(tmp_path):
    bag = small_bag(tmp_path / "a.bag")
    with pytest.raises(
        ValueError,
        match=r"a\.bag: no topic '/velodyne_points' \(--lidar-topic\); "
        r"sensor_msgs/msg/PointCloud2 topics: /points",
    ):
        open_dataset(bag, options=LoadOptions(lidar_topics=["/velodyne_points"]))
    with pytest.raises(
        ValueError,
        match=r"topic '/imu' \(--lidar-topic\) is sensor_msgs/msg/Imu; expected "
        r"sensor_msgs/msg/PointCloud2",
    ):
        open_dataset(bag, options=LoadOptions(lidar_topics=["/imu"]))
    with pytest.raises(ValueError, match=r"no topic '/imu0' \(--imu-topic\); sensor_msgs/msg/Imu topics: /imu"):
        open_dataset(bag, options=LoadOptions(imu_topic="/imu0"))


def test_cloud_without_xyz_names_its_fields(tmp_path):
    bag = small_bag(tmp_path / "b", "sqlite3", fields=("a", "b", "c"))
    with pytest.raises(
        ValueError,
        match=r"topic /points .*no field 'x', 'y', 'z' \(fields: a, b, c\); "
        r"expected x, y, z",
    ):
        open_dataset(bag)


def test_unknown_time_unit_names_the_field(tmp_path):
    # Velodyne's float32 'time' spanning 50: seconds would make a 50 s scan
    bag = small_bag(tmp_path / "c.bag", times=np.linspace(0.0, 50.0, 50), convention="velodyne")
    with pytest.raises(ValueError, match=r"c\.bag topic /points .*time field 'time' \(float32\) .*unknown time unit"):
        open_dataset(bag)
    ds = open_dataset(bag, options=LoadOptions(time=TimeOptions(field="none")))
    assert len(ds.scan(0).time_s) == 0


def test_no_time_field_warns_and_skips_undistortion(tmp_path):
    folder_scan = farlio.Scan(np.ones((4, 3), np.float32))
    path = tmp_path / "d.bag"
    with BagWriter(path) as w:
        for k in range(2):
            w.cloud(
                "/points",
                "lidar",
                k * 100_000_000 + 1,
                (k + 1) * 100_000_000 + 1,
                np.asarray(folder_scan.points),
                None,
                None,
                "none",
            )
    ds = open_dataset(path)
    assert any("no per-point time field" in m and "/points" in m for m in ds.warnings())
    assert len(ds.scan(1).time_s) == 0 and ds.scan(1).end_stamp_ns == 200_000_001


@pytest.mark.parametrize("storage", ["ros1", "mcap", "sqlite3"])
def test_truncated_bag_is_a_clear_error(sequence, tmp_path, storage, capsys):
    bag = write_dataset(
        open_dataset(sequence), tmp_path / ("t.bag" if storage == "ros1" else "t"), storage, max_scans=4
    )
    file = bag if storage == "ros1" else next(p for p in bag.iterdir() if p.suffix in (".mcap", ".db3"))
    data = file.read_bytes()
    file.write_bytes(data[: len(data) // 2])
    with pytest.raises((ValueError, BagError), match=re.escape(str(bag)) + ".*(truncated|corrupt)"):
        ds = open_dataset(bag)
        for i in range(len(ds)):
            ds.scan(i)
    assert main(["run", str(bag), "--out", str(tmp_path / "out"), "--no-progress", "--no-plot"]) == 2
    err = capsys.readouterr().err
    assert "farlio run: error:" in err and "Traceback" not in err


def test_extrinsic_chain_and_calib_file(tmp_path):
    T_imu_base = farlio.SE3.exp(np.array([0.1, 0.0, 0.2, 0.0, 0.0, 0.3]))
    T_base_lidar = farlio.SE3.exp(np.array([0.5, 0.1, 1.0, 0.02, 0.0, -0.1]))
    path = tmp_path / "e.bag"
    with BagWriter(path) as w:
        w.tf_static(1, [("base_link", "os_sensor", T_base_lidar), ("base_link", "imu_link", T_imu_base.inverse())])
        w.imu("/imu", "imu_link", [farlio.ImuSample(10 + k, np.zeros(3), np.array([0, 0, 9.81])) for k in range(3)])
        w.cloud("/points", "/os_sensor", 100, 200, np.ones((3, 3), np.float32), np.zeros(3), None)
    expected = (T_imu_base * T_base_lidar).matrix()
    np.testing.assert_allclose(open_dataset(path).T_imu_lidar().matrix(), expected, atol=1e-9)
    calib = tmp_path / "calib.yaml"
    calib.write_text("T_imu_lidar:\n  /points: [[1, 0, 0, 1.5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n")
    got = open_dataset(path, options=LoadOptions(calib=calib)).T_imu_lidar().matrix()
    assert got[0, 3] == pytest.approx(1.5)


def test_per_point_times_past_the_scan_are_skipped_by_farlio_run(tmp_path, capsys):
    """Times that reach 5 periods (0.5 s of a 0.1 s scan: within the decoder's 1 s span rule) fail
    the check every loader shares (check_point_times), which the bag loader runs on its scans:
    `farlio run` skips them with a warning."""
    from farlio.cli import main as cli

    bag = small_bag(tmp_path / "t.bag", times=np.linspace(0.0, 0.5, 50), convention="velodyne")
    assert cli(["run", str(bag), "--out", str(tmp_path / "out"), "--no-progress", "--no-plot"]) == 0
    err = capsys.readouterr().err
    assert "skipping t.bag" in err or "skipping " + str(bag) in err, err
    # all three clouds: their times (0.5 s in a 0.1 s period) reach back before the scan start
    assert err.count(": per-point times start at -0.1 s, before the scan start") == 3, err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["skipped"] == summary["frames"] == 3
