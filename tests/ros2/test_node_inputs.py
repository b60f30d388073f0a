"""`farlio ros2` on other inputs over loopback: two LiDAR topics merged back into one scan per period,
a LiDAR clock off the IMU clock undone by time_offset_s, clouds that cannot be used (no x/y/z,
only NaN, a repeated stamp) reported without stopping the node, and SIGTERM."""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest

pytest.importorskip("rclpy")

from farlio._core import NS_PER_S  # noqa: E402
from farlio.datasets.pointcloud2_encode import encode  # noqa: E402
from loopback import START_TIMEOUT_S, play, wait_for, wait_for_diagnostics  # noqa: E402

SCANS = 20
#: between the hand-made clouds: longer than a scan takes
PACE_S = 0.3
#: the player shifts the LiDAR stamps by this (its clock ahead of the IMU's)
LIDAR_SHIFT_S = 0.05


def stamp(msg) -> int:
    return msg.header.stamp.sec * NS_PER_S + msg.header.stamp.nanosec


def run_node(urban, recorder, start_node, *params: str, play_args: tuple[str, ...] = ()):
    """Plays SCANS scans of the urban sequence into a node; the node's diagnostics."""
    path, _ = urban
    node = start_node(f"calib_file:={path / 'calib.yaml'}", *params)
    recorder.wait_for_node(node)
    played = play(path, "--max-scans", str(SCANS), *play_args)
    wait_for_diagnostics(recorder, SCANS, node, played)
    assert node.stop() == 0
    return recorder.diagnostics()


def test_two_lidar_topics_merge_into_one_scan_per_period(urban, recorder, start_node):
    _, ds = urban
    diags = run_node(
        urban,
        recorder,
        start_node,
        "lidar_topics:=[/front,/rear]",
        play_args=("--lidar-topic", "/front", "--lidar-topic", "/rear"),
    )
    assert len(diags) == SCANS and all(d["processed"] == "True" for d in diags), [
        (d["stamp_ns"], d["message"], d["latency_ms"], d["pipeline_ms"]) for d in diags[:5]
    ][:2] + [(d["stamp_ns"], d["message"], d["latency_ms"], d["pipeline_ms"]) for d in diags[:5]][2:3]
    # both halves of every scan (after the first, which ends at its first half's last point)
    assert [int(d["input_points"]) for d in diags[1:]] == [len(ds.scan(i)) for i in range(1, SCANS)]
    assert [stamp(m) for _, m in recorder.msgs["scan_odometry"]][1:] == [
        ds.scan(i).end_stamp_ns for i in range(1, SCANS)
    ]


def test_time_offset_puts_the_lidar_stamps_on_the_imu_clock(urban, recorder, start_node):
    _, ds = urban
    run_node(
        urban,
        recorder,
        start_node,
        f"time_offset_s:={-LIDAR_SHIFT_S}",
        play_args=("--lidar-time-shift", str(LIDAR_SHIFT_S)),
    )
    # the scans are stamped on the IMU clock: the recording's own end stamps
    got = [stamp(m) for _, m in recorder.msgs["scan_odometry"]]
    assert got[1:] == [ds.scan(i).end_stamp_ns for i in range(1, SCANS)]


def test_unusable_clouds_are_reported_and_the_node_goes_on(urban, recorder, start_node, ros):
    from farlio.ros2.conversions import cloud_msg
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import PointCloud2

    _, ds = urban
    node = start_node("imu_topic:=none")  # LiDAR-only: the clouds alone drive it
    pub = recorder.node.create_publisher(
        PointCloud2, "/points", QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    )
    recorder.wait_for_node(node)
    wait_for(lambda: pub.get_subscription_count() > 0, START_TIMEOUT_S, "the node's subscription")

    def cloud(i: int, names=None, nan=False):
        s = ds.scan(i)
        pts = np.asarray(s.points)
        if nan:  # a sweep without one valid return
            pts = np.full_like(pts, np.nan)
        msg = cloud_msg(encode(pts, np.asarray(s.time_s), None, s.start_stamp_ns, s.end_stamp_ns), "lidar")
        for f, name in zip(msg.fields, names or []):
            f.name = name
        return msg

    # scan 1 without x/y/z, scan 1 again (a repeated stamp), scan 2 only NaN; with each good scan,
    # the number of scan odometry messages it must bring (None: a bad cloud, nothing to wait for)
    sequence = [
        (cloud(0), 1),
        (cloud(1), 2),
        (cloud(1, names=["a", "b", "c"]), None),
        (cloud(1), None),
        (cloud(2, nan=True), None),
        (cloud(3), 3),
    ]
    # one at a time: LiDAR-only, a scan arriving while one is processed is dropped, so each good
    # scan's result is awaited (a loaded machine can take longer than PACE_S for a scan)
    for msg, expected in sequence:
        pub.publish(msg)
        if expected is None:
            time.sleep(PACE_S)
        else:
            what = f"{expected} scan odometry messages"
            wait_for(lambda n=expected: recorder.count("scan_odometry") >= n, START_TIMEOUT_S, what)
    assert node.alive()
    assert node.stop() == 0
    last = recorder.diagnostics()[-1]
    counts = (last["clouds_undecodable"], last["clouds_out_of_order"], last["clouds_empty"])
    assert counts == ("1", "1", "1"), last
    assert recorder.count("scan_odometry") == 3
    assert last["mode"] == "lidar-only"
    log = node.text()
    assert "no field 'x'" in log and "LiDAR-only" in log and "Traceback" not in log, log


def test_sigterm_stops_the_node_cleanly(recorder, start_node):
    # what `ros2 launch` sends after SIGINT: the same clean stop, counters printed, exit status 0
    node = start_node("imu_topic:=none")
    recorder.wait_for_node(node)
    assert node.stop(signal.SIGTERM) == 0
    log = node.text()
    assert "farlio stopped" in log and "Traceback" not in log, log
