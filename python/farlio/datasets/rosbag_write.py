"""Writes recordings as ROS bags with `rosbags` (ROS 1 .bag, ROS 2 sqlite3 or MCAP): PointCloud2
with the per-point time convention of a chosen driver, sensor_msgs/Imu and /tf_static. Used by the
tests and benchmarks to produce bags whose content is known exactly; `write_dataset` converts any
farlio dataset (e.g. a sequence folder) into a bag.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

import farlio
from farlio._core import NS_PER_S

from .pointcloud2_encode import encode

STORAGES = ("ros1", "sqlite3", "mcap")
ROS2_BAG_VERSION = 9
TFMESSAGE = "tf2_msgs/msg/TFMessage"
TFMESSAGE_DEFINITION = "geometry_msgs/TransformStamped[] transforms"


class BagWriter:
    """`with BagWriter(path, 'mcap') as w: w.cloud(...); w.imu(...); w.tf_static(...)`."""

    def __init__(self, path: Path, storage: str = "ros1"):
        from rosbags.typesys import Stores, get_types_from_msg, get_typestore

        if storage not in STORAGES:
            raise ValueError(f"unknown bag storage '{storage}'; expected one of {', '.join(STORAGES)}")
        self.path, self.storage = Path(path), storage
        self.ros1 = storage == "ros1"
        self.ts = get_typestore(Stores.ROS1_NOETIC if self.ros1 else Stores.ROS2_HUMBLE)
        if TFMESSAGE not in self.ts.types:  # the ROS 1 store lacks tf2_msgs
            self.ts.register(get_types_from_msg(TFMESSAGE_DEFINITION, TFMESSAGE))
        if self.ros1:
            from rosbags.rosbag1 import Writer

            self._writer = Writer(self.path)
        else:
            from rosbags.rosbag2 import StoragePlugin, Writer

            plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
            self._writer = Writer(self.path, version=ROS2_BAG_VERSION, storage_plugin=plugin)
        self._conns: dict[str, Any] = {}
        self._seq = 0

    def __enter__(self) -> BagWriter:
        self._writer.open()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._writer.close()

    def _type(self, name: str) -> Any:
        return self.ts.types[name]

    def _header(self, stamp: int, frame: str) -> Any:
        time = self._type("builtin_interfaces/msg/Time")(sec=stamp // NS_PER_S, nanosec=stamp % NS_PER_S)
        self._seq += 1
        extra = {"seq": self._seq} if self.ros1 else {}
        return self._type("std_msgs/msg/Header")(stamp=time, frame_id=frame, **extra)

    def _write(self, topic: str, msgtype: str, stamp: int, msg: Any) -> None:
        if topic not in self._conns:
            self._conns[topic] = self._writer.add_connection(topic, msgtype, typestore=self.ts)
        data = self.ts.serialize_ros1(msg, msgtype) if self.ros1 else self.ts.serialize_cdr(msg, msgtype)
        self._writer.write(self._conns[topic], stamp, data)

    def cloud(
        self,
        topic: str,
        frame: str,
        start_ns: int,
        end_ns: int,
        points: np.ndarray,
        time_s: np.ndarray | None,
        intensity: np.ndarray | None,
        convention: str = "ouster",
        padding: int = 0,
    ) -> None:
        """One PointCloud2; time_s: per-point time in s since start_ns. `padding` bytes are left
        unnamed at the end of every point (as drivers do for alignment)."""
        enc = encode(points, time_s, intensity, start_ns, end_ns, convention, padding)
        field_type = self._type("sensor_msgs/msg/PointField")
        fields = [field_type(name=n, offset=o, datatype=d, count=1) for n, o, d in enc.fields]
        msgtype = "sensor_msgs/msg/PointCloud2"
        msg = self._type(msgtype)(
            header=self._header(enc.header_ns, frame),
            height=1,
            width=enc.width,
            fields=fields,
            is_bigendian=False,
            point_step=enc.point_step,
            row_step=len(enc.data),
            data=enc.data,
            is_dense=True,
        )
        self._write(topic, msgtype, end_ns, msg)

    def imu(self, topic: str, frame: str, samples: list[farlio.ImuSample]) -> None:
        v3 = self._type("geometry_msgs/msg/Vector3")
        q = self._type("geometry_msgs/msg/Quaternion")(x=0.0, y=0.0, z=0.0, w=1.0)
        msgtype = "sensor_msgs/msg/Imu"
        cov = np.zeros(9)
        for s in samples:
            g, a = s.gyro_rad_s, s.accel_m_s2
            msg = self._type(msgtype)(
                header=self._header(s.stamp_ns, frame),
                orientation=q,
                orientation_covariance=cov,
                angular_velocity=v3(x=g[0], y=g[1], z=g[2]),
                angular_velocity_covariance=cov,
                linear_acceleration=v3(x=a[0], y=a[1], z=a[2]),
                linear_acceleration_covariance=cov,
            )
            self._write(topic, msgtype, s.stamp_ns, msg)

    def tf_static(self, stamp_ns: int, transforms: list[tuple[str, str, farlio.SE3]]) -> None:
        """(parent, child, T_parent_child) on /tf_static."""
        v3, quat = self._type("geometry_msgs/msg/Vector3"), self._type("geometry_msgs/msg/Quaternion")
        stamped, tr = self._type("geometry_msgs/msg/TransformStamped"), self._type("geometry_msgs/msg/Transform")
        items = []
        for parent, child, T in transforms:
            t, qv = T.translation, T.quaternion_xyzw
            items.append(
                stamped(
                    header=self._header(stamp_ns, parent),
                    child_frame_id=child,
                    transform=tr(
                        translation=v3(x=t[0], y=t[1], z=t[2]), rotation=quat(x=qv[0], y=qv[1], z=qv[2], w=qv[3])
                    ),
                )
            )
        self._write("/tf_static", TFMESSAGE, stamp_ns, self._type(TFMESSAGE)(transforms=items))


def write_dataset(
    dataset: Any,
    path: Path,
    storage: str = "ros1",
    convention: str = "ouster",
    *,
    lidar_topic: str = "/points",
    imu_topic: str = "/imu",
    lidar_frame: str = "lidar",
    imu_frame: str = "imu",
    max_scans: int | None = None,
    padding: int = 0,
) -> Path:
    """Writes a farlio dataset (scans, IMU, T_imu_lidar on /tf_static) as a bag."""
    n = len(dataset) if max_scans is None else min(max_scans, len(dataset))
    imu = dataset.imu()
    with BagWriter(path, storage) as w:
        first = dataset.scan(0)
        w.tf_static(first.start_stamp_ns, [(imu_frame, lidar_frame, dataset.T_imu_lidar())])
        if imu:
            w.imu(imu_topic, imu_frame, imu)
        for i in range(n):
            s = first if i == 0 else dataset.scan(i)
            time_s = np.asarray(s.time_s) if len(s.time_s) else None
            inten = np.asarray(s.intensity) if len(s.intensity) else None
            w.cloud(
                lidar_topic,
                lidar_frame,
                s.start_stamp_ns,
                s.end_stamp_ns,
                np.asarray(s.points),
                time_s,
                inten,
                convention,
                padding,
            )
    return Path(path)
