"""A generated urban sequence played in real time over loopback into `farlio ros2`: the recorded
/farlio/odometry against the ground truth (APE and RPE within 1.5x of `farlio run` on the same
sequence), the 10 ms odometry grid, one scan odometry per scan with the scan's stamp, the frames,
the map service, and a clean stop on SIGINT."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rclpy")

import farlio  # noqa: E402
from farlio import _core  # noqa: E402
from farlio._core import NS_PER_S  # noqa: E402
from farlio.datasets.calib import se3_from_quaternion  # noqa: E402
from farlio.evaluation import evaluate_files  # noqa: E402
from farlio.runner import ODOMETRY_TUM, run_dataset  # noqa: E402
from loopback import play, wait_for_diagnostics  # noqa: E402

#: the live odometry may be this much worse than the replay of `farlio run`
ACCURACY_FACTOR = 1.5
#: RPE over pairs this far apart along the ground truth
RPE_DELTA_M = 1.0
STEP_NS = 10_000_000  # fusion.step_s
#: the first scan's end is its last point's time (no previous header to give the period)
FIRST_END_TOLERANCE_NS = 2_000_000


def accuracy(estimate, groundtruth) -> tuple[float, float]:
    """(APE translation RMSE m, RPE translation RMSE m over RPE_DELTA_M) of a TUM file."""
    acc = evaluate_files(estimate, groundtruth, plot=False, rpe_delta=RPE_DELTA_M, rpe_unit="m")
    return acc["ape"]["translation_m"]["rmse"], acc["rpe"]["translation_m"]["rmse"]


def test_urban_over_loopback_matches_farlio_run(urban, recorder, start_node, tmp_path):
    path, ds = urban
    map_file = tmp_path / "map.ply"
    # the shipped parameter file, read by rcl's parser, with overrides
    params_file = Path(farlio.__file__).parent / "ros2" / "share" / "params.yaml"
    node = start_node(f"calib_file:={path / 'calib.yaml'}", f"map_file:={map_file}", params_file=params_file)
    recorder.wait_for_node(node)
    played = play(path)
    n = len(ds)
    wait_for_diagnostics(recorder, n, node, played)

    response = recorder.save_map()
    assert response.success, response.message
    saved = _core.io.read_point_cloud(map_file)  # the submap after the last scan
    assert len(saved) == int(recorder.diagnostics()[-1]["map_points"]) > 0

    assert node.stop() == 0  # SIGINT: a clean stop
    log = node.text()
    assert "farlio stopped" in log and "Traceback" not in log, log

    # every scan processed and reported once, its scan odometry stamped at the scan end
    diags = recorder.diagnostics()
    assert [d["processed"] for d in diags] == ["True"] * n, [d["message"] for d in diags]
    ends = [ds.scan(i).end_stamp_ns for i in range(n)]
    scan_stamps = [farlio_stamp(m) for _, m in recorder.msgs["scan_odometry"]]
    assert len(scan_stamps) == n
    assert scan_stamps[1:] == ends[1:]
    assert abs(scan_stamps[0] - ends[0]) < FIRST_END_TOLERANCE_NS
    clouds = [m for _, m in recorder.msgs["cloud_registered"]]
    assert [farlio_stamp(m) for m in clouds] == scan_stamps and all(m.header.frame_id == "odom" for m in clouds)

    # the fused odometry: every 10 ms step, in order, frames of REP 105, nothing beyond the IMU
    odom = [m for _, m in recorder.msgs["odometry"]]
    stamps = np.array([farlio_stamp(m) for m in odom])
    imu = ds.imu()
    assert np.all(np.diff(stamps) == STEP_NS)
    assert len(stamps) > 0.9 * (imu[-1].stamp_ns - ends[0]) / STEP_NS
    assert stamps[-1] <= imu[-1].stamp_ns
    for m in (*odom, *(m for _, m in recorder.msgs["scan_odometry"])):
        assert (m.header.frame_id, m.child_frame_id) == ("odom", "base_link")

    # accuracy against the ground truth, next to the replay of the same sequence
    recorded = tmp_path / "ros_odometry.tum"
    writer = _core.io.TrajectoryWriter(recorded)
    for m in odom:
        p, q = m.pose.pose.position, m.pose.pose.orientation
        writer.append(farlio_stamp(m), se3_from_quaternion([p.x, p.y, p.z], [q.x, q.y, q.z, q.w]))
    del writer
    gt = path / "groundtruth.tum"
    run_dataset(ds, tmp_path / "run", plot=False, progress=False)
    ape_run, rpe_run = accuracy(tmp_path / "run" / ODOMETRY_TUM, gt)
    ape_ros, rpe_ros = accuracy(recorded, gt)
    print(f"APE farlio run {ape_run:.4f} m, ROS {ape_ros:.4f} m; RPE {rpe_run:.5f} m, {rpe_ros:.5f} m")
    assert ape_ros <= ACCURACY_FACTOR * ape_run
    assert rpe_ros <= ACCURACY_FACTOR * rpe_run


def farlio_stamp(msg) -> int:
    return msg.header.stamp.sec * NS_PER_S + msg.header.stamp.nanosec
