"""`farlio ros2-play`: publishes any recording `farlio run` reads (farlio.datasets) as ROS 2 topics,
paced by its stamps (real time, or `rate` times faster): sensor_msgs/Imu at every sample's stamp,
sensor_msgs/PointCloud2 at every scan's end (when a driver could first send it), with the per-point
time convention of a chosen driver. For users without rosbag2, and for the tests and benchmarks.

Several LiDAR topics: every scan is split by azimuth into equal sectors, one per topic (all in the
one LiDAR frame), a stand-in for several LiDARs that the node merges back into one scan.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, PointCloud2

import farlio
from farlio._core import NS_PER_S

from ..datasets import Dataset
from ..datasets.pointcloud2_encode import encode
from . import WAIT_SUBSCRIBERS_S
from . import conversions as conv

PLAYER_NODE = "farlio_play"
#: how long the end of the recording waits for subscribers to acknowledge everything
ACK_TIMEOUT_S = 5.0
#: publishers' history depth
CLOUD_DEPTH, IMU_DEPTH = 5, 200
#: a subscriber is looked for this often while waiting for one
DISCOVERY_POLL_S = 0.05


@dataclass
class PlayOptions:
    lidar_topics: list[str] = field(default_factory=lambda: ["/points"])
    imu_topic: str = "/imu"  # '' : no IMU published
    lidar_frame: str = "lidar"
    imu_frame: str = "imu"
    convention: str = "ouster"  # per-point time convention (farlio.datasets.pointcloud2_encode)
    rate: float = 1.0  # times real time
    lidar_time_shift_s: float = 0.0  # added to the LiDAR stamps (a LiDAR clock off the IMU's)
    wait_subscribers_s: float = WAIT_SUBSCRIBERS_S  # wait up to this for a subscriber on every topic
    max_scans: int | None = None
    clock: bool = False  # also publish /clock (for use_sim_time)


@dataclass
class PlayStats:
    scans: int = 0
    clouds: int = 0
    imu: int = 0
    wall_s: float = 0.0
    late_s: float = 0.0  # the most a message was published after its due time
    #: scan end stamp (as published) -> monotonic ns when its clouds were published
    sent_ns: dict[int, int] = field(default_factory=dict)


def sector_split(points: np.ndarray, parts: int) -> list[np.ndarray]:
    """Indices of the points in each of `parts` equal azimuth sectors."""
    if parts == 1:
        return [np.arange(len(points))]
    sector = np.floor((np.arctan2(points[:, 1], points[:, 0]) + math.pi) / (2 * math.pi) * parts).astype(int)
    sector = np.clip(sector, 0, parts - 1)
    return [np.flatnonzero(sector == k) for k in range(parts)]


class Player:
    """Publishes one dataset; `play()` returns what was published."""

    _start: float = 0.0  # monotonic time of the first message
    _first: int = 0  # its stamp

    def __init__(self, node: Node, dataset: Dataset, options: PlayOptions):
        self.node, self.dataset, self.options = node, dataset, options
        reliable = ReliabilityPolicy.RELIABLE
        self.cloud_pubs = [
            node.create_publisher(PointCloud2, t, QoSProfile(depth=CLOUD_DEPTH, reliability=reliable))
            for t in options.lidar_topics
        ]
        self.imu = dataset.imu() if options.imu_topic else []
        self.imu_pub = (
            node.create_publisher(Imu, options.imu_topic, QoSProfile(depth=IMU_DEPTH, reliability=reliable))
            if options.imu_topic
            else None
        )
        self.clock_pub = node.create_publisher(Clock, "/clock", IMU_DEPTH) if options.clock else None
        n = len(dataset)
        self.scans = n if options.max_scans is None else min(n, options.max_scans)
        self.shift_ns = int(round(options.lidar_time_shift_s * NS_PER_S))
        self.stats = PlayStats()

    def publishers(self) -> list[Any]:
        return [*self.cloud_pubs, *([self.imu_pub] if self.imu_pub else [])]

    def wait_for_subscribers(self) -> bool:
        deadline = time.monotonic() + self.options.wait_subscribers_s
        while time.monotonic() < deadline:
            if all(p.get_subscription_count() > 0 for p in self.publishers()):
                return True
            time.sleep(DISCOVERY_POLL_S)
        return False

    def cloud_messages(self, scan: farlio.Scan) -> list[PointCloud2]:
        """The scan as one cloud per LiDAR topic (azimuth sectors), stamps shifted by the LiDAR offset."""
        points = np.asarray(scan.points)
        times = np.asarray(scan.time_s) if len(scan.time_s) else None
        inten = np.asarray(scan.intensity) if len(scan.intensity) else None
        start, end = scan.start_stamp_ns + self.shift_ns, scan.end_stamp_ns + self.shift_ns
        out = []
        for idx in sector_split(points, len(self.cloud_pubs)):
            enc = encode(
                points[idx],
                None if times is None else times[idx],
                None if inten is None else inten[idx],
                start,
                end,
                self.options.convention,
            )
            out.append(conv.cloud_msg(enc, self.options.lidar_frame))
        return out

    def play(self) -> PlayStats:
        """Scan after scan (the next one read and encoded while waiting): the IMU samples up to its
        end, then its clouds; the IMU samples after the last scan at the end."""
        scan = self.dataset.scan(0) if self.scans else None
        stamps = [s.stamp_ns for s in self.imu[:1]] + ([scan.end_stamp_ns] if scan is not None else [])
        if not stamps:
            return self.stats
        self._start, self._first = time.monotonic(), min(stamps)
        msgs = self.cloud_messages(scan) if scan is not None else []
        end = scan.end_stamp_ns if scan is not None else 0
        k = 0
        for i in range(self.scans):
            while k < len(self.imu) and self.imu[k].stamp_ns <= end:
                self._publish_imu(k)
                k += 1
            self._wait_until(end)
            for pub, msg in zip(self.cloud_pubs, msgs):
                pub.publish(msg)
                self.stats.clouds += 1
            self.stats.sent_ns[end + self.shift_ns] = time.monotonic_ns()
            self.stats.scans += 1
            if i + 1 < self.scans:
                nxt = self.dataset.scan(i + 1)
                msgs, end = self.cloud_messages(nxt), nxt.end_stamp_ns
        while k < len(self.imu):
            self._publish_imu(k)
            k += 1
        self.stats.wall_s = time.monotonic() - self._start
        for p in self.publishers():
            p.wait_for_all_acked(Duration(seconds=ACK_TIMEOUT_S))
        return self.stats

    def _wait_until(self, stamp: int) -> None:
        delay = self._start + (stamp - self._first) / NS_PER_S / self.options.rate - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        else:
            self.stats.late_s = max(self.stats.late_s, -delay)

    def _publish_imu(self, k: int) -> None:
        sample = self.imu[k]
        self._wait_until(sample.stamp_ns)
        self.imu_pub.publish(conv.imu_msg(sample, self.options.imu_frame))
        self.stats.imu += 1
        if self.clock_pub is not None:
            self.clock_pub.publish(Clock(clock=conv.to_stamp(sample.stamp_ns)))


def play(dataset: Dataset, options: PlayOptions, ros_args: list[str] | None = None) -> PlayStats:
    """Publishes `dataset` from a node of its own (rclpy initialised and shut down here)."""
    rclpy.init(args=[PLAYER_NODE, *(ros_args or [])])
    node = Node(PLAYER_NODE)
    try:
        player = Player(node, dataset, options)
        if options.wait_subscribers_s > 0 and not player.wait_for_subscribers():
            node.get_logger().warning(
                f"no subscriber on every topic after {options.wait_subscribers_s} s: playing anyway "
                "(messages before the subscribers are discovered are lost)"
            )
        return player.play()
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
