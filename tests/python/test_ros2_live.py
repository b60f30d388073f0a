"""The ROS 2 node's input handling without ROS (farlio.ros2.live): live scans as `farlio run` makes
them, several LiDAR topics merged, bad inputs counted instead of crashing, the wait for the IMU.
The node itself, over loopback, is tested in tests/ros2."""

from __future__ import annotations

from types import SimpleNamespace

import farlio
import numpy as np
import pytest
from farlio._core import NS_PER_S
from farlio.datasets import open_dataset
from farlio.datasets.pointcloud2_encode import encode
from farlio.ros2.live import LiveOdometry
from farlio.ros2.params import NodeParams, config_from, default_params_yaml, node_params_from
from farlio.simulation import generate

SCANS = 8


@pytest.fixture(scope="module")
def urban(tmp_path_factory):
    path = tmp_path_factory.mktemp("live") / "urban"
    generate("urban", path, duration_s=1.0)
    ds = open_dataset(path)
    thin = [ds.scan(i) for i in range(SCANS)]
    return ds, thin


def message(points, time_s, start_ns, end_ns, convention="ouster", fields=None):
    """A PointCloud2 as rclpy or rosbags give it (the attributes decode reads)."""
    enc = encode(points, time_s, None, start_ns, end_ns, convention)
    names = fields or [f[0] for f in enc.fields]
    return SimpleNamespace(
        header=SimpleNamespace(stamp=SimpleNamespace(sec=enc.header_ns // NS_PER_S, nanosec=enc.header_ns % NS_PER_S)),
        fields=[SimpleNamespace(name=n, offset=o, datatype=d, count=1) for (_, o, d), n in zip(enc.fields, names)],
        is_bigendian=False,
        point_step=enc.point_step,
        row_step=len(enc.data),
        width=enc.width,
        height=1,
        data=enc.data.tobytes(),
    )


def scan_message(scan, idx=None, shift_ns=0, **kw):
    pts, t = np.asarray(scan.points), np.asarray(scan.time_s)
    if idx is not None:
        pts, t = pts[idx], t[idx]
    return message(pts, t, scan.start_stamp_ns + shift_ns, scan.end_stamp_ns + shift_ns, **kw)


class Clock:
    def __init__(self):
        self.ns = 0

    def __call__(self) -> int:
        return self.ns


def live(ds, warnings, clock=None, **params):
    p = node_params_from({"lidar_topics": ["/points"], **params})
    return LiveOdometry(
        farlio.Config(), p, [ds.T_imu_lidar()] * len(p.lidar_topics), 9.81, warnings.append, clock=clock or Clock()
    )


def feed(node, ds, scans, msgs_of):
    """IMU up to each scan end, then its messages (topic index, message); returns the frames."""
    imu, k, frames = ds.imu(), 0, []
    for scan in scans:
        while k < len(imu) and imu[k].stamp_ns <= scan.end_stamp_ns:
            node.add_imu(imu[k])
            k += 1
        for index, msg in msgs_of(scan):
            node.add_cloud(index, msg)
        node.odometry.wait_idle()
        frames += node.wait_frames(0.0)
    node.stop()
    return frames + node.wait_frames(0.0)


def test_live_scans_have_the_recording_stamps_after_the_first(urban):
    ds, scans = urban
    warnings = []
    node = live(ds, warnings)
    frames = feed(node, ds, scans, lambda s: [(0, scan_message(s))])
    assert [f.frame.scan.stamp_ns for f in frames[1:]] == [s.end_stamp_ns for s in scans[1:]]
    # the first has no previous header: its end is its last point's time
    assert abs(frames[0].frame.scan.stamp_ns - scans[0].end_stamp_ns) < 2_000_000
    assert all(f.frame.processed for f in frames) and node.odometry.inertial
    assert node.stats.scans == SCANS and not warnings


def test_two_topics_merge_into_one_scan_per_period(urban):
    ds, scans = urban
    warnings = []
    node = live(ds, warnings, lidar_topics=["/front", "/rear"])

    def halves(s):
        x = np.asarray(s.points)[:, 0]
        return [(0, scan_message(s, np.flatnonzero(x >= 0))), (1, scan_message(s, np.flatnonzero(x < 0)))]

    frames = feed(node, ds, scans, halves)
    assert len(frames) == SCANS
    # every point of both halves is in its scan (none lost, none taken twice); the first scan ends
    # at its reference half's last point (no period known yet): the other half's later points wait
    assert [f.frame.scan.input_points for f in frames[1:]] == [len(s.points) for s in scans[1:]]
    assert frames[0].frame.scan.input_points <= len(scans[0].points)
    assert [f.frame.scan.stamp_ns for f in frames[1:]] == [s.end_stamp_ns for s in scans[1:]]


def test_time_offset_moves_lidar_stamps_onto_the_imu_clock(urban):
    ds, scans = urban
    shift_ns = 37_000_000  # the LiDAR clock runs 37 ms ahead of the IMU clock
    node = live(ds, [], time_offset_s=-shift_ns / NS_PER_S)
    frames = feed(node, ds, scans, lambda s: [(0, scan_message(s, shift_ns=shift_ns))])
    assert [f.frame.scan.stamp_ns for f in frames[1:]] == [s.end_stamp_ns for s in scans[1:]]


def test_bad_clouds_and_stamps_are_counted_not_fatal(urban):
    ds, scans = urban
    warnings = []
    node = live(ds, warnings)
    s0 = scans[0]
    pts = np.asarray(s0.points)

    def inputs(s):
        if s is scans[2]:  # no x/y/z fields, then only NaN points, then a repeated stamp
            yield 0, scan_message(s, fields=["a", "b", "c", "t"])
            nan = np.full_like(pts, np.nan)
            yield 0, message(nan, np.asarray(s0.time_s), s.start_stamp_ns - 1, s.end_stamp_ns - 1)
        yield 0, scan_message(s)
        if s is scans[3]:
            yield 0, scan_message(s)  # duplicated

    frames = feed(node, ds, scans, inputs)
    st = node.stats
    assert (st.clouds_undecodable, st.clouds_empty, st.clouds_out_of_order) == (1, 1, 1)
    assert len(frames) == SCANS and all(f.frame.processed for f in frames)
    assert any("no field 'x'" in w for w in warnings)
    # IMU: a repeated stamp and a NaN sample are dropped
    imu = ds.imu()[-1]
    node.add_imu(imu)
    assert node.add_imu(imu) == [] and st.imu_out_of_order == 1
    bad = farlio.ImuSample(imu.stamp_ns + 1, np.array([np.nan, 0, 0]), imu.accel_m_s2)
    assert node.add_imu(bad) == [] and st.imu_non_finite == 1


def test_without_imu_the_odometry_runs_lidar_only_after_the_wait(urban):
    ds, scans = urban
    warnings, clock = [], Clock()
    node = live(ds, warnings, clock=clock, imu_wait_s=0.25)
    period_ns = 100_000_000
    for i, s in enumerate(scans[:5]):
        clock.ns = i * period_ns
        node.add_cloud(0, scan_message(s))
        node.odometry.wait_idle()
    node.stop()
    frames = node.wait_frames(0.0)
    assert node.stats.scans_before_imu == 3  # at 0, 0.1, 0.2 s; the scan at 0.3 s starts LiDAR-only
    assert len(frames) == 2 and not node.odometry.inertial
    assert sum("LiDAR-only" in w for w in warnings) == 1


def test_parameters_name_every_config_field_and_check_values():
    text = default_params_yaml()
    for name, *_ in farlio.Config.fields():
        assert f"    {name}: " in text
    assert config_from({"map.voxel_size_m": 2}).get("map.voxel_size_m") == 2.0
    with pytest.raises(ValueError, match="map.voxel_size_m"):
        config_from({"map.voxel_size_m": -1.0})
    assert node_params_from({"time_offset_s": 1}).time_offset_s == 1.0
    for bad in ({"input_qos": "fast"}, {"lidar_topics": []}, {"time_unit": "h"}, {"imu_wait_s": -1.0}):
        with pytest.raises(ValueError):
            node_params_from(bad)
    assert NodeParams().uses_imu and not node_params_from({"imu_topic": "none"}).uses_imu


def test_a_silent_topic_is_reported_once_per_silence(urban):
    ds, scans = urban
    clock = Clock()
    node = live(ds, [], clock=clock, silent_topic_timeout_s=0.5)
    clock.ns = 400_000_000
    assert node.silent_topics() == ([], [])
    clock.ns = 600_000_000  # nothing since the start
    fell, _ = node.silent_topics()
    assert sorted(fell) == ["/imu", "/points"] and not node.has_seen("/imu")
    assert node.silent_topics() == ([], [])  # reported once
    node.add_imu(ds.imu()[0])
    assert node.silent_topics() == ([], ["/imu"])
    clock.ns = 1_200_000_000
    assert node.silent_topics() == (["/imu"], []) and node.stats.silent_topics == 3
    node.stop()
