"""ROS 1 bags (.bag) and ROS 2 bags (a folder with metadata.yaml, or one .db3 / .mcap file), read
with the `rosbags` package (pure Python; no ROS installation).

Topics: with exactly one sensor_msgs/PointCloud2 and at most one sensor_msgs/Imu topic they are
chosen automatically; otherwise `LoadOptions.lidar_topics` / `imu_topic` name them (the error
lists what the bag has). Several LiDAR topics are merged into one scan per period of the first
(lidar_merge.py): the points of the others whose times fall into that period, moved into the
first LiDAR's frame with their extrinsics, each point keeping its own time and a sensor id (the
topic's index).

Extrinsics: `--calib` file first, else /tf_static (the chain from the IMU message frame to each
cloud's frame), else identity with a warning. Scans are read in one sequential pass (a backward
access restarts it); IMU and /tf_static are read when the bag is opened.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

import farlio

from .base import Dataset, LoadOptions
from .calib import CalibFile, se3_from_quaternion
from .lidar_merge import TimedClouds, assemble, caught_up, scan_interval
from .pointcloud2 import TIME_FIELDS, Cloud, CloudError, decode, field_names, stamp_ns, time_field_of

POINTCLOUD2 = "sensor_msgs/msg/PointCloud2"
IMU = "sensor_msgs/msg/Imu"
TFMESSAGE = "tf2_msgs/msg/TFMessage"
TF_STATIC_TOPIC = "/tf_static"
ROS1_SUFFIX = ".bag"
ROS2_SUFFIXES = (".db3", ".mcap")
ROS2_METADATA = "metadata.yaml"
#: ouster-ros packet messages: such bags are read by the Ouster dataloader (datasets/ouster.py)
OUSTER_PACKET_TYPES = ("ouster_ros/msg/PacketMsg", "ouster_sensor_msgs/msg/PacketMsg", "ouster_msgs/msg/PacketMsg")


class BagError(RuntimeError):
    """A bag that cannot be read further (corrupt or truncated): fatal for a run."""


def is_bag_path(path: Path) -> bool:
    path = Path(path)
    if path.is_file():
        return path.suffix == ROS1_SUFFIX or path.suffix in ROS2_SUFFIXES
    return path.is_dir() and (path / ROS2_METADATA).is_file()


def open_bag(path: Path) -> Any:
    """An opened rosbags AnyReader; any failure becomes a ValueError naming the bag."""
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError:
        raise ValueError(
            f"{path}: reading ROS bags needs the 'rosbags' package: pip install rosbags (or pip install 'farlio[ros]')"
        ) from None
    try:
        reader = AnyReader([Path(path)], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as e:  # rosbags raises many types for corrupt or truncated files
        raise ValueError(
            f"{path}: cannot open as a ROS bag ({type(e).__name__}: {e}); a truncated or corrupt bag, or not a bag"
        ) from None
    return reader


def describe_topics(reader: Any) -> str:
    seen: dict[str, list[Any]] = {}
    for c in reader.connections:
        seen.setdefault(c.topic, []).append(c)
    return (
        ", ".join(f"{t} ({cs[0].msgtype}, {sum(c.msgcount for c in cs)} msgs)" for t, cs in sorted(seen.items()))
        or "none"
    )


def bag_messages(reader: Any, path: Path, connections: list[Any]) -> Iterator[tuple[Any, int, Any]]:
    """(connection, bag time ns, deserialised message); read errors become BagError naming the bag."""
    if not connections:  # rosbags reads every topic when given none
        return
    it = reader.messages(connections=connections)
    while True:
        try:
            conn, t, raw = next(it)
        except StopIteration:
            return
        except Exception as e:
            raise BagError(f"{path}: reading failed ({type(e).__name__}: {e}); truncated or corrupt bag?") from None
        try:
            msg = reader.deserialize(raw, conn.msgtype)
        except Exception as e:
            raise BagError(
                f"{path}: topic {conn.topic}: cannot deserialise a {conn.msgtype} message at {t} ns "
                f"({type(e).__name__}: {e})"
            ) from None
        yield conn, t, msg


def _frame(name: str) -> str:
    return name.lstrip("/")


def tf_lookup(edges: list[tuple[str, str, farlio.SE3]], target: str, source: str) -> farlio.SE3 | None:
    """T_target_source through a tree of (parent, child, T_parent_child) edges; None when unconnected."""
    known = {target: farlio.SE3()}
    queue = deque([target])
    while queue:
        a = queue.popleft()
        if a == source:
            return known[a]
        for parent, child, T in edges:
            if parent == a and child not in known:
                known[child] = known[a] * T
                queue.append(child)
            elif child == a and parent not in known:
                known[parent] = known[a] * T.inverse()
                queue.append(parent)
    return None


class RosBag(Dataset):
    """A ROS 1 or ROS 2 bag with sensor_msgs/PointCloud2 scans and optionally sensor_msgs/Imu."""

    @classmethod
    def matches(cls, path: Path) -> bool:
        return is_bag_path(path)

    def __init__(self, path: Path, options: LoadOptions | None = None):
        self.path = Path(path)
        self.options = options or LoadOptions()
        self._warnings: list[str] = []
        self._reader = open_bag(self.path)
        by_topic: dict[str, list[Any]] = {}
        for c in self._reader.connections:
            by_topic.setdefault(c.topic, []).append(c)
        self._by_topic = by_topic
        self.lidar_topics = self._choose_lidar_topics()
        self.imu_topic = self._choose_imu_topic()
        self._length = sum(c.msgcount for c in by_topic[self.lidar_topics[0]])
        firsts = [self._first_cloud(t) for t in self.lidar_topics]
        self.frames = [_frame(m.header.frame_id) for m in firsts]
        for topic, msg in zip(self.lidar_topics, firsts):
            decode(msg, f"{self.path} topic {topic} first message", self.options.time)  # bad fields fail here
            if time_field_of(msg, self.options.time) is None:
                self._warnings.append(
                    f"{self.path}: topic {topic} has no per-point time field (fields: "
                    f"{', '.join(field_names(msg))}; looked for {', '.join(TIME_FIELDS)}): "
                    f"its scans are not undistorted"
                )
        self._has_time = all(time_field_of(m, self.options.time) is not None for m in firsts)
        self.imu_frame = ""
        self._imu = self._read_imu()
        self._extrinsics = self._read_extrinsics()
        self._gen: Iterator[farlio.Scan | Exception] | None = None
        self._next = 0

    # --- topics -------------------------------------------------------------------------------
    def _topics_of(self, msgtype: str) -> list[str]:
        return sorted(t for t, cs in self._by_topic.items() if cs[0].msgtype == msgtype)

    def _check_topic(self, topic: str, msgtype: str, option: str) -> None:
        if topic not in self._by_topic:
            raise ValueError(
                f"{self.path}: no topic '{topic}' ({option}); {msgtype} topics: "
                f"{', '.join(self._topics_of(msgtype)) or 'none'}; all topics: "
                f"{describe_topics(self._reader)}"
            )
        found = self._by_topic[topic][0].msgtype
        if found != msgtype:
            raise ValueError(f"{self.path}: topic '{topic}' ({option}) is {found}; expected {msgtype}")
        if sum(c.msgcount for c in self._by_topic[topic]) == 0:
            raise ValueError(f"{self.path}: topic '{topic}' ({option}) has no messages")

    def _choose_lidar_topics(self) -> list[str]:
        topics = list(self.options.lidar_topics)
        for t in topics:
            self._check_topic(t, POINTCLOUD2, "--lidar-topic")
        if topics:
            return topics
        found = self._topics_of(POINTCLOUD2)
        if len(found) == 1:
            return found
        if not found:
            raise ValueError(f"{self.path}: no {POINTCLOUD2} topic; topics: {describe_topics(self._reader)}")
        raise ValueError(
            f"{self.path}: {len(found)} {POINTCLOUD2} topics ({', '.join(found)}): pass --lidar-topic "
            f"(repeat it to merge several LiDARs)"
        )

    def _choose_imu_topic(self) -> str | None:
        topic = self.options.imu_topic
        if topic == "none":
            return None
        if topic:
            self._check_topic(topic, IMU, "--imu-topic")
            return topic
        found = self._topics_of(IMU)
        if len(found) == 1:
            return found[0]
        if not found:
            self._warnings.append(f"{self.path}: no {IMU} topic: LiDAR-only odometry")
            return None
        raise ValueError(
            f"{self.path}: {len(found)} {IMU} topics ({', '.join(found)}): pass --imu-topic "
            f"(or --imu-topic none for LiDAR-only)"
        )

    def _first_cloud(self, topic: str) -> Any:
        for _, _, msg in bag_messages(self._reader, self.path, self._by_topic[topic]):
            return msg
        raise ValueError(f"{self.path}: topic '{topic}' has no messages")

    # --- IMU and extrinsics ---------------------------------------------------------------------
    def _read_imu(self) -> list[farlio.ImuSample]:
        if self.imu_topic is None:
            return []
        samples = []
        for _, t, msg in bag_messages(self._reader, self.path, self._by_topic[self.imu_topic]):
            self.imu_frame = _frame(msg.header.frame_id)
            w, a = msg.angular_velocity, msg.linear_acceleration
            stamp = stamp_ns(msg.header) or t
            samples.append(farlio.ImuSample(stamp, np.array([w.x, w.y, w.z]), np.array([a.x, a.y, a.z])))
        samples.sort(key=lambda s: s.stamp_ns)
        return samples

    def gravity_m_s2(self) -> float:
        if self.options.calib is not None and CalibFile(self.options.calib).gravity_m_s2 is not None:
            return CalibFile(self.options.calib).gravity_m_s2
        return super().gravity_m_s2()

    def _read_extrinsics(self) -> list[farlio.SE3]:
        if self.options.calib is not None:
            calib = CalibFile(self.options.calib)
            return [calib.T_imu_lidar(t, f) for t, f in zip(self.lidar_topics, self.frames)]
        if self.imu_topic is None and len(self.lidar_topics) == 1:
            return [farlio.SE3()]
        edges = []
        for _, _, msg in bag_messages(self._reader, self.path, self._by_topic.get(TF_STATIC_TOPIC, [])):
            for tr in msg.transforms:
                t, q = tr.transform.translation, tr.transform.rotation
                edges.append(
                    (
                        _frame(tr.header.frame_id),
                        _frame(tr.child_frame_id),
                        se3_from_quaternion((t.x, t.y, t.z), (q.x, q.y, q.z, q.w)),
                    )
                )
        body = self.imu_frame if self.imu_topic is not None else self.frames[0]
        out = []
        for topic, frame in zip(self.lidar_topics, self.frames):
            T = farlio.SE3() if frame == body else tf_lookup(edges, body, frame)
            if T is None:
                self._warnings.append(
                    f"{self.path}: no extrinsic from LiDAR frame '{frame}' ({topic}) to the IMU frame '{body}' in "
                    f"{TF_STATIC_TOPIC} ({len(edges)} transforms) and no --calib: assuming identity"
                )
                T = farlio.SE3()
            out.append(T)
        return out

    # --- Dataset ---------------------------------------------------------------------------------
    def __len__(self) -> int:
        return self._length

    def imu(self) -> list[farlio.ImuSample]:
        return self._imu

    def T_imu_lidar(self) -> farlio.SE3:
        return self._extrinsics[0]

    def warnings(self) -> list[str]:
        return list(self._warnings)

    def scan_source(self, i: int) -> str:
        return f"{self.path} topic {self.lidar_topics[0]} message {i}"

    def scan(self, i: int) -> farlio.Scan:
        if self._gen is None or i < self._next:
            self._gen, self._next = self._scans(), 0
        item: farlio.Scan | Exception | None = None
        while self._next <= i:
            item = next(self._gen, None)
            if item is None:
                raise ValueError(
                    f"{self.path}: topic {self.lidar_topics[0]} ended after {self._next} messages (scan {i} asked)"
                )
            self._next += 1
        if isinstance(item, Exception):
            raise item
        farlio._core.io.check_point_times(item, self.scan_source(i))  # the check of every loader
        return item

    # --- the sequential pass ---------------------------------------------------------------------
    def _clouds(self) -> Iterator[tuple[int, Cloud | CloudError]]:
        index = {t: k for k, t in enumerate(self.lidar_topics)}
        conns = [c for t in self.lidar_topics for c in self._by_topic[t]]
        for conn, t, msg in bag_messages(self._reader, self.path, conns):
            try:
                yield (
                    index[conn.topic],
                    decode(msg, f"{self.path} topic {conn.topic} message at {t} ns", self.options.time),
                )
            except CloudError as e:
                yield index[conn.topic], e

    def _scans(self) -> Iterator[farlio.Scan | Exception]:
        clouds = self._clouds()
        refs: deque[Cloud | CloudError] = deque()
        others: list[TimedClouds] = [deque() for _ in self.lidar_topics[1:]]
        done = False

        def pull() -> None:
            nonlocal done
            item = next(clouds, None)
            if item is None:
                done = True
            elif item[0] == 0:
                refs.append(item[1])
            elif isinstance(item[1], Cloud):
                others[item[0] - 1].append((item[1], item[1].absolute_ns()))

        prev: tuple[int, int] | None = None
        while True:
            while len(refs) < 2 and not done:
                pull()
            if not refs:
                return
            cur = refs.popleft()
            if isinstance(cur, Exception):
                yield cur
                continue
            nxt = next((c for c in refs if isinstance(c, Cloud)), None)
            start, end = scan_interval(cur, nxt, prev)
            while others and not done and not caught_up(others, end):
                pull()
            yield assemble(cur, start, end, others, self._extrinsics, self._has_time)
            prev = (start, end)
