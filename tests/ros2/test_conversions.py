"""The node's message conversions with the real ROS 2 message types (no node, no transport): the
reused Odometry message, the registered cloud's PointCloud2 read back, and a PointCloud2 as a
subscription delivers it (data an array.array) decoded like its numpy twin."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rclpy")

import farlio  # noqa: E402
from farlio._core import NS_PER_S  # noqa: E402
from farlio.datasets.pointcloud2 import decode  # noqa: E402
from farlio.datasets.pointcloud2_encode import encode  # noqa: E402
from farlio.ros2 import conversions as conv  # noqa: E402
from rclpy.serialization import deserialize_message, serialize_message  # noqa: E402
from sensor_msgs.msg import PointCloud2  # noqa: E402

STAMP_NS = 1_700_000_000_987_654_321


def test_reused_odometry_sets_every_pose_and_refuses_non_finite_ones():
    out = conv.ReusedOdometry("odom", "base_link")
    first = farlio.SE3.exp(np.array([1.0, -2.0, 3.0, 0.1, -0.2, 0.3]))
    assert out.fill(STAMP_NS, first, np.array([0.5, 0.25, -1.0]), [0.01, 0.02, 0.03])
    msg = out.msg
    assert (msg.header.frame_id, msg.child_frame_id) == ("odom", "base_link")
    assert msg.header.stamp.sec * NS_PER_S + msg.header.stamp.nanosec == STAMP_NS
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    np.testing.assert_array_equal([p.x, p.y, p.z], first.translation)
    np.testing.assert_array_equal([o.x, o.y, o.z, o.w], first.quaternion_xyzw)
    t = msg.twist.twist
    assert [t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z] == [
        0.5,
        0.25,
        -1.0,
        0.01,
        0.02,
        0.03,
    ]

    second = farlio.SE3.exp(np.array([4.0, 5.0, 6.0, 0.0, 0.0, 1.0]))
    assert out.fill(STAMP_NS + 10_000_000, second)  # no twist given: the pose changes, the twist stays
    assert out.msg is msg and msg.header.stamp.nanosec == (STAMP_NS + 10_000_000) % NS_PER_S
    np.testing.assert_array_equal([p.x, p.y, p.z], second.translation)
    assert t.linear.x == 0.5

    bad = farlio.SE3.exp(np.array([math.nan, 0.0, 0.0, 0.0, 0.0, 0.0]))
    assert not out.fill(STAMP_NS + 20_000_000, bad)
    assert msg.header.stamp.nanosec == (STAMP_NS + 10_000_000) % NS_PER_S  # unchanged
    np.testing.assert_array_equal([p.x, p.y, p.z], second.translation)


def test_registered_cloud_reads_back_as_its_points():
    points = np.random.default_rng(5).uniform(-50, 50, (1000, 3)).astype(np.float32)
    msg = deserialize_message(serialize_message(conv.points_msg(points, STAMP_NS, "odom")), PointCloud2)
    assert [(f.name, f.offset, f.datatype) for f in msg.fields] == [("x", 0, 7), ("y", 4, 7), ("z", 8, 7)]
    assert (msg.point_step, msg.width, msg.height, msg.header.frame_id) == (12, 1000, 1, "odom")
    cloud = decode(msg, "cloud_registered")
    np.testing.assert_array_equal(cloud.points, points)
    assert cloud.stamp_ns == STAMP_NS and cloud.offset_s is None


def test_a_received_cloud_decodes_like_its_numpy_twin():
    rng = np.random.default_rng(6)
    points = rng.uniform(-50, 50, (5000, 3)).astype(np.float32)
    points[10] = 0.0  # no return
    time_s = np.sort(rng.uniform(0, 0.1, 5000))
    enc = encode(points, time_s, rng.uniform(0, 100, 5000).astype(np.float32), STAMP_NS, STAMP_NS + 10**8, "hesai", 4)
    msg = deserialize_message(serialize_message(conv.cloud_msg(enc, "lidar")), PointCloud2)
    assert type(msg.data).__name__ == "array"  # what a subscription callback gets
    twin = decode(msg, "twin")
    msg.data = np.frombuffer(msg.data, np.uint8).copy()
    reference = decode(msg, "numpy")
    np.testing.assert_array_equal(twin.points, reference.points)
    np.testing.assert_array_equal(twin.offset_s, reference.offset_s)
    assert len(twin.points) == 4999
    assert np.abs(twin.absolute_ns() - (STAMP_NS + np.round(np.delete(time_s, 10) * 1e9))).max() < 500
