"""farlio._core.io from Python: round trips through the bound readers and writers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")
io = core.io

POINTS = 500
SEED = 3


def random_scan(end_stamp_ns: int = 0) -> core.Scan:
    rng = np.random.default_rng(SEED)
    pts = rng.uniform(-50.0, 50.0, (POINTS, 3)).astype(np.float32)
    t = rng.uniform(0.0, 0.1, POINTS).astype(np.float32)
    intensity = rng.uniform(0.0, 255.0, POINTS).astype(np.float32)
    return core.Scan(pts, time_s=t, intensity=intensity, end_stamp_ns=end_stamp_ns)


@pytest.mark.parametrize("encoding", ["ascii", "binary", "binary_compressed"])
def test_pcd_round_trip(tmp_path: Path, encoding: str) -> None:
    scan = random_scan()
    path = tmp_path / "a.pcd"
    io.write_pcd(path, scan, encoding)
    back = io.read_point_cloud(path)
    np.testing.assert_array_equal(back.points, scan.points)
    np.testing.assert_array_equal(back.time_s, scan.time_s)
    np.testing.assert_array_equal(back.intensity, scan.intensity)


def test_bad_encoding_and_bad_file(tmp_path: Path) -> None:
    with pytest.raises(ValueError):
        io.write_pcd(tmp_path / "a.pcd", random_scan(), "zip")
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"12345")
    with pytest.raises(core.InputError, match="bad.bin"):
        io.read_point_cloud(bad)


def test_ply_and_kitti_bin(tmp_path: Path) -> None:
    scan = random_scan()
    io.write_ply(tmp_path / "m.ply", scan)
    np.testing.assert_array_equal(io.read_point_cloud(tmp_path / "m.ply").points, scan.points)
    io.write_kitti_bin(str(tmp_path / "k.bin"), scan)
    np.testing.assert_array_equal(io.read_point_cloud(tmp_path / "k.bin").intensity, scan.intensity)


def test_trajectories_and_writer(tmp_path: Path) -> None:
    traj = core.Trajectory()
    for i in range(5):
        xi = np.array([i, 0.5 * i, 0.0, 0.0, 0.0, 0.1 * i])
        traj.push_back(1_700_000_000_000_000_000 + i * 100_000_001, core.SE3.exp(xi))
    io.write_tum(tmp_path / "a.tum", traj)
    back = io.read_tum(tmp_path / "a.tum")
    np.testing.assert_array_equal(back.stamps_ns, traj.stamps_ns)
    np.testing.assert_allclose(back.matrices(), traj.matrices(), atol=1e-12)
    io.write_kitti(tmp_path / "a.txt", traj)
    kitti = io.read_kitti(tmp_path / "a.txt", list(traj.stamps_ns))
    np.testing.assert_array_equal(kitti.stamps_ns, traj.stamps_ns)
    writer = io.TrajectoryWriter(tmp_path / "live.tum")
    writer.append(traj[0][0], traj[0][1])
    assert len(io.read_tum(tmp_path / "live.tum")) == 1


def test_sequence_round_trip(tmp_path: Path) -> None:
    writer = io.SequenceWriter(tmp_path / "seq")
    calib = io.Calibration()
    calib.gravity_m_s2 = 9.8
    writer.write_calibration(calib)
    ends = [1_000_000_000, 1_100_000_000, 1_200_000_000]
    for e in ends:
        writer.write_scan(random_scan(e), "binary_compressed")
    writer.write_imu([core.ImuSample(900_000_000 + k, np.zeros(3), np.array([0.0, 0.0, 9.8])) for k in range(3)])
    writer.write_meta({"profile": "test"})
    reader = io.SequenceReader(tmp_path / "seq")
    assert len(reader) == 3
    scan = reader.read_scan(1)
    assert (scan.start_stamp_ns, scan.end_stamp_ns) == (ends[0], ends[1])
    assert len(reader.imu()) == 3
    assert reader.calibration().gravity_m_s2 == 9.8
    assert reader.groundtruth() is None
    with pytest.raises(core.InputError, match="lidar"):
        io.SequenceReader(tmp_path)


def test_ns_per_s_is_one_integer_for_every_module() -> None:
    from farlio.datasets import kitti_raw, pointcloud2

    assert core.NS_PER_S == 1_000_000_000 and isinstance(core.NS_PER_S, int)
    assert pointcloud2.NS_PER_S is core.NS_PER_S and kitti_raw.NS_PER_S is core.NS_PER_S


def test_times_files_and_trajectories_by_format(tmp_path: Path) -> None:
    (tmp_path / "times.txt").write_text("# s\n1700000000.000000001\n1700000000.100000001, extra\n")
    assert io.read_stamps(tmp_path / "times.txt") == [1_700_000_000_000_000_001, 1_700_000_000_100_000_001]
    traj = core.Trajectory()
    for stamp in io.read_stamps(tmp_path / "times.txt"):
        traj.push_back(stamp, core.SE3.exp(np.array([stamp % 7, 0.0, 0.0, 0.0, 0.0, 0.1])))
    io.write_kitti(tmp_path / "poses.txt", traj)
    io.write_tum(tmp_path / "poses.tum", traj)
    for path, times in ((tmp_path / "poses.txt", tmp_path / "times.txt"), (tmp_path / "poses.tum", None)):
        back = io.read_trajectory(path, "auto", times)
        np.testing.assert_array_equal(back.stamps_ns, traj.stamps_ns)
    assert io.read_trajectory(tmp_path / "poses.txt").stamps_ns[1] == 100_000_000
    with pytest.raises(ValueError, match="unknown trajectory format 'csv'"):
        io.read_trajectory(tmp_path / "poses.txt", "csv")
    with pytest.raises(core.InputError, match="times.txt:2"):
        (tmp_path / "times.txt").write_text("1.0\nnope\n")
        io.read_stamps(tmp_path / "times.txt")


def test_torn_last_line_is_skipped_with_a_warning(tmp_path: Path) -> None:
    """A disk-full run leaves a partial last line: the readers skip it with a UserWarning naming
    the file and line, and `farlio eval` evaluates the rest (it used to reject the whole file)."""
    est = tmp_path / "odometry_body.tum"
    lines = [f"{k}.0 {k} 0 0 0 0 0 1" for k in range(1, 6)]
    est.write_text("\n".join(lines) + "\n6.0 6 0")
    with pytest.warns(UserWarning, match=r"odometry_body\.tum:6: last line skipped"):
        traj = io.read_trajectory(est)
    assert len(traj) == 5
    gt = tmp_path / "gt.tum"
    gt.write_text("\n".join(lines) + "\n")
    # a bad line in the middle is still an error
    bad = tmp_path / "bad.tum"
    bad.write_text("\n".join([lines[0], "2.0 x", *lines[2:]]) + "\n6.0 6 0")
    with pytest.raises(ValueError, match=r"bad\.tum:2"):
        io.read_trajectory(bad)


def test_eval_cli_warns_about_a_torn_line_and_evaluates(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    from farlio import cli

    lines = [f"{k}.0 {k} {k * k * 0.1} 0 0 0 0 1" for k in range(1, 11)]
    est, gt = tmp_path / "est.tum", tmp_path / "gt.tum"
    est.write_text("\n".join(lines) + "\n11.0 11 12.1 0 0")
    gt.write_text("\n".join(lines) + "\n")
    assert cli.main(["eval", str(est), str(gt), "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "farlio: warning: " in err and "est.tum:11: last line skipped" in err


def test_trajectory_writer_says_why_a_write_failed() -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full")
    with pytest.raises(RuntimeError, match="/dev/full: write error: No space left on device"):
        io.TrajectoryWriter("/dev/full")
    with pytest.raises(RuntimeError, match="/dev/full: write error: No space left on device"):
        io.write_tum("/dev/full", core.Trajectory())
