"""ROS 2 messages <-> farlio and numpy: stamps, sensor_msgs/Imu, sensor_msgs/PointCloud2 (decoded by
farlio.datasets.pointcloud2, encoded by farlio.datasets.pointcloud2_encode), nav_msgs/Odometry and
geometry_msgs/TransformStamped. Needs the ROS 2 message packages (the node and the player import it).
"""

from __future__ import annotations

import array
import math
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, PointCloud2, PointField

import farlio
from farlio._core import NS_PER_S
from farlio.datasets.pointcloud2_encode import EncodedCloud, encode


def stamp_ns(stamp: Time) -> int:
    return int(stamp.sec) * NS_PER_S + int(stamp.nanosec)


def to_stamp(ns: int) -> Time:
    return Time(sec=int(ns // NS_PER_S), nanosec=int(ns % NS_PER_S))


def imu_sample(msg: Imu, offset_ns: int = 0) -> farlio.ImuSample:
    """The sample of an Imu message (angular rate, specific force), its stamp shifted by offset_ns."""
    w, a = msg.angular_velocity, msg.linear_acceleration
    return farlio.ImuSample(
        stamp_ns(msg.header.stamp) + offset_ns, np.array([w.x, w.y, w.z]), np.array([a.x, a.y, a.z])
    )


def imu_msg(sample: farlio.ImuSample, frame: str) -> Imu:
    msg = Imu()
    msg.header.stamp = to_stamp(sample.stamp_ns)
    msg.header.frame_id = frame
    msg.orientation_covariance[0] = -1.0  # no orientation (REP 145)
    g, a = sample.gyro_rad_s, sample.accel_m_s2
    msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = (float(v) for v in g)
    msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = (float(v) for v in a)
    return msg


def cloud_msg(enc: EncodedCloud, frame: str) -> PointCloud2:
    """A PointCloud2 (height 1, little endian) from encoded points."""
    msg = PointCloud2()
    msg.header.stamp = to_stamp(enc.header_ns)
    msg.header.frame_id = frame
    msg.height, msg.width = 1, enc.width
    msg.fields = [PointField(name=n, offset=o, datatype=d, count=1) for n, o, d in enc.fields]
    msg.is_bigendian = False
    msg.point_step = enc.point_step
    msg.row_step = len(enc.data)
    data = array.array("B")
    data.frombytes(enc.data.data)  # one copy; assigning an array.array('B') skips rclpy's per-item check
    msg.data = data
    msg.is_dense = True
    return msg


def points_msg(points: np.ndarray, stamp: int, frame: str) -> PointCloud2:
    """x, y, z float32 points (N, 3) as a PointCloud2 stamped `stamp` (ns)."""
    return cloud_msg(encode(np.asarray(points, dtype=np.float32), None, None, stamp, stamp, "none"), frame)


class ReusedOdometry:
    """One nav_msgs/Odometry of the body (pose in odom_frame, twist in base_frame, REP 105), filled
    again for every pose: about 5x cheaper than a new message each time (5 against 25 us with the
    finiteness check, the nested messages and covariance arrays being built once). Publishing
    serialises the message at once, so it can be reused right after; one per publishing thread."""

    def __init__(self, odom_frame: str, base_frame: str):
        self.msg = Odometry()
        self.msg.header.frame_id = odom_frame
        self.msg.child_frame_id = base_frame

    def fill(
        self,
        stamp: int,
        pose: farlio.SE3,
        velocity_body_m_s: Any = None,
        angular_velocity_body_rad_s: Any = None,
    ) -> bool:
        """Sets the stamp (ns), the pose and, when given, the twist. False, the message left as it
        was, when the pose is not finite."""
        t, q = pose.translation.tolist(), pose.quaternion_xyzw.tolist()
        if not all(map(math.isfinite, t + q)):
            return False
        msg = self.msg
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp), NS_PER_S)
        position, orientation = msg.pose.pose.position, msg.pose.pose.orientation
        position.x, position.y, position.z = t
        orientation.x, orientation.y, orientation.z, orientation.w = q
        if velocity_body_m_s is not None:
            lin = msg.twist.twist.linear
            lin.x, lin.y, lin.z = map(float, velocity_body_m_s)
        if angular_velocity_body_rad_s is not None:
            ang = msg.twist.twist.angular
            ang.x, ang.y, ang.z = map(float, angular_velocity_body_rad_s)
        return True


def transform_msg(stamp: int, pose: farlio.SE3, parent: str, child: str) -> TransformStamped:
    msg = TransformStamped()
    msg.header.stamp = to_stamp(stamp)
    msg.header.frame_id = parent
    msg.child_frame_id = child
    t, q = pose.translation, pose.quaternion_xyzw
    tr = msg.transform
    tr.translation.x, tr.translation.y, tr.translation.z = (float(v) for v in t)
    tr.rotation.x, tr.rotation.y, tr.rotation.z, tr.rotation.w = (float(v) for v in q)
    return msg


def pose_of(msg: Odometry) -> tuple[int, np.ndarray, np.ndarray]:
    """(stamp ns, position (3,), quaternion xyzw (4,)) of an Odometry message."""
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    return stamp_ns(msg.header.stamp), np.array([p.x, p.y, p.z]), np.array([o.x, o.y, o.z, o.w])
