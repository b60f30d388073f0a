"""What the ROS 2 node does with its inputs, without ROS: decoded IMU samples and PointCloud2
messages in, scans for the online odometry (farlio.OnlineOdometry, the one pipeline) out, and
every input that cannot be used counted and reported instead of crashing the node.

- IMU samples go to the odometry in time order; a sample that is not after the previous one
  (duplicated or going back) or holds NaN/Inf is dropped and counted.
- Clouds are decoded by farlio.datasets.pointcloud2 (the bag loader's auto-detection of the time
  field, its unit and the header stamp meaning), shifted by time_offset_s onto the IMU clock, and
  made into scans by farlio.datasets.lidar_merge (several LiDARs merged per period of the first,
  as `farlio run` does). Undecodable clouds (no x/y/z, bad layout), clouds out of order, points
  with NaN/Inf and clouds left empty are dropped and counted.
- With an IMU topic, scans wait for the first IMU sample (dropped meanwhile) for imu_wait_s; after
  that the odometry starts LiDAR-only, with one warning.
- A topic without messages for silent_topic_timeout_s is reported once per silence.
Reports go to `warn` at the 1st, 10th, 100th, ... occurrence of each kind.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, Callable

import numpy as np

import farlio
from farlio._core import NS_PER_S

from ..datasets.lidar_merge import TimedClouds, assemble, live_interval
from ..datasets.pointcloud2 import Cloud, CloudError, decode, time_field_of
from ..mapping import MapOptions, load_prior_map
from .params import NodeParams

#: clouds of another LiDAR kept while the reference LiDAR is silent
MAX_BUFFERED_CLOUDS = 20
#: another LiDAR whose period ends within this of the reference's end has sent its part of the scan
MERGE_SLACK_S = 0.005
#: a scan this far from the newest IMU stamp means unsynchronised clocks (or a wrong time_offset_s)
MAX_CLOCK_DIFFERENCE_S = 1.0
#: reports of one kind are logged at these multiples of a power of ten (1, 10, 100, ...)
REPORT_BASE = 10


def _is_power(n: int, base: int) -> bool:
    """Whether n is base**k for some k >= 0."""
    while n > 1 and n % base == 0:
        n //= base
    return n == 1


@dataclass
class Counters:
    """What happened to the inputs and outputs (published with the diagnostics)."""

    imu_samples: int = 0
    imu_out_of_order: int = 0
    imu_non_finite: int = 0
    clouds: int = 0
    clouds_out_of_order: int = 0
    clouds_undecodable: int = 0
    clouds_empty: int = 0
    points_non_finite: int = 0
    scans: int = 0
    scans_before_imu: int = 0
    scans_out_of_order: int = 0
    scans_clock_mismatch: int = 0
    silent_topics: int = 0
    poses_non_finite: int = 0
    scans_lost: int = 0  # localization: scans that did not match the prior map
    callback_errors: int = 0

    def as_dict(self) -> dict[str, int]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


@dataclass
class FrameReport:
    """A scan's result with when its (reference) cloud arrived and when the result was taken (the
    node moves done_ns to when it has published the scan odometry), ns of the monotonic clock."""

    frame: Any  # farlio._core.OdometryFrame
    arrival_ns: int
    done_ns: int

    @property
    def latency_s(self) -> float:
        return (self.done_ns - self.arrival_ns) / NS_PER_S


class LiveOdometry:
    """The online odometry fed from live messages (see the module doc)."""

    def __init__(
        self,
        config: farlio.Config,
        params: NodeParams,
        extrinsics: list[farlio.SE3],
        gravity_m_s2: float,
        warn: Callable[[str], None],
        keep_registered_points: bool = False,
        clock: Callable[[], int] = time.monotonic_ns,
    ):
        self.params = params
        self.topics = list(params.lidar_topics)
        self.extrinsics = extrinsics
        self.warn = warn
        self.clock = clock
        self.stats = Counters()
        self.odometry = farlio.OnlineOdometry(config, extrinsics[0], gravity_m_s2, keep_registered_points)
        # localization in a prior map (parameters prior_map, initial_pose), as `farlio run --prior-map`
        requested_pose = list(params.initial_pose) if any(params.initial_pose) else None
        load_prior_map(self.odometry, MapOptions(prior_map=Path(params.prior_map) if params.prior_map else None,
                                                 initial_pose=requested_pose))  # fmt: skip
        self._time_options = params.time_options()
        self._offset_ns = int(round(params.time_offset_s * NS_PER_S))
        self._refs: deque[tuple[Cloud, int, tuple[int, int]]] = deque()  # reference clouds, arrival, interval
        self._others: list[TimedClouds] = [deque() for _ in self.topics[1:]]
        self._has_time: list[bool | None] = [None] * len(self.topics)  # per topic, from its first cloud
        self._last_cloud_ns: list[int | None] = [None] * len(self.topics)
        self._prev_header: list[int | None] = [None] * len(self.topics)  # previous header stamp per topic
        self._period_end: list[int] = [0] * len(self.topics)  # where the newest cloud's period ends
        self._last_scan_end: int | None = None
        self._last_imu_ns: int | None = None
        self.last_gyro_rad_s = np.zeros(3)
        self._first_cloud_at: int | None = None
        self._lidar_only_warned = False
        self._arrivals: dict[int, int] = {}  # scan end stamp -> arrival of its reference cloud
        start = clock()
        self._last_seen = {t: start for t in self._input_topics()}
        self._seen: set[str] = set()
        self._silent: set[str] = set()
        if not params.uses_imu:
            self._warn_lidar_only(f"imu_topic is '{params.imu_topic}'")

    @property
    def last_scan_end(self) -> int | None:
        """End stamp (ns) of the newest scan handed to the odometry."""
        return self._last_scan_end

    def _input_topics(self) -> list[str]:
        return ([self.params.imu_topic] if self.params.uses_imu else []) + self.topics

    def report(self, kind: str, message: str) -> None:
        """Counts one `kind` (a Counters field) and warns at its 1st, 10th, 100th, ... time."""
        n = getattr(self.stats, kind) + 1
        setattr(self.stats, kind, n)
        if _is_power(n, REPORT_BASE):
            self.warn(f"{message} ({kind}: {n} so far)")

    def _warn_lidar_only(self, why: str) -> None:
        if not self._lidar_only_warned:
            self._lidar_only_warned = True
            self.warn(f"{why}: LiDAR-only odometry (no IMU)")

    # --- IMU -----------------------------------------------------------------------------------
    def add_imu(self, sample: farlio.ImuSample) -> list[Any]:
        """Feeds one IMU sample; returns the odometry samples (farlio OdometrySample) it completed."""
        self._seen_now(self.params.imu_topic, self.clock())
        if not (np.isfinite(sample.gyro_rad_s).all() and np.isfinite(sample.accel_m_s2).all()):
            self.report("imu_non_finite", f"{self.params.imu_topic}: IMU sample with NaN/Inf dropped")
            return []
        if self._last_imu_ns is not None and sample.stamp_ns <= self._last_imu_ns:
            self.report(
                "imu_out_of_order",
                f"{self.params.imu_topic}: IMU stamp {sample.stamp_ns} ns is not after the previous "
                f"{self._last_imu_ns} ns: sample dropped",
            )
            return []
        self._last_imu_ns = sample.stamp_ns
        self.last_gyro_rad_s = np.asarray(sample.gyro_rad_s)
        self.stats.imu_samples += 1
        self.odometry.add_imu(sample)
        self.poll()
        return self.odometry.take_odometry()

    # --- clouds --------------------------------------------------------------------------------
    def add_cloud(self, index: int, msg: Any) -> None:
        """A PointCloud2 (rclpy message or any object with its attributes) of lidar_topics[index]."""
        now = self.clock()
        topic = self.topics[index]
        self._seen_now(topic, now)
        self.stats.clouds += 1
        try:
            cloud = decode(msg, f"{topic}", self._time_options)
        except CloudError as e:
            self.report("clouds_undecodable", f"cloud dropped: {e}")
            return
        cloud.stamp_ns += self._offset_ns
        last = self._last_cloud_ns[index]
        if last is not None and cloud.stamp_ns <= last:
            self.report(
                "clouds_out_of_order",
                f"{topic}: cloud stamp {cloud.stamp_ns} ns is not after the previous {last} ns: cloud dropped",
            )
            return
        self._last_cloud_ns[index] = cloud.stamp_ns
        interval = live_interval(cloud, self._prev_header[index])
        self._prev_header[index], self._period_end[index] = cloud.stamp_ns, interval[1]
        if self._has_time[index] is None:
            self._has_time[index] = time_field_of(msg, self._time_options) is not None
            if not self._has_time[index]:
                self.warn(f"{topic}: no per-point time field: its scans are not undistorted")
        if index == 0:
            self._refs.append((cloud, now, interval))
        else:
            q = self._others[index - 1]
            q.append((cloud, cloud.absolute_ns()))
            while len(q) > MAX_BUFFERED_CLOUDS:
                q.popleft()
        self.poll()

    def poll(self) -> None:
        """Assembles the scans whose clouds are complete (or have waited lidar_merge_wait_s)."""
        wait_ns = int(self.params.lidar_merge_wait_s * NS_PER_S)
        while self._refs:
            cloud, arrival, (start, end) = self._refs[0]
            if not self._others_caught_up(cloud.stamp_ns, end) and self.clock() - arrival < wait_ns:
                return
            self._refs.popleft()
            has_time = all(self._has_time)
            self._submit(assemble(cloud, start, end, self._others, self.extrinsics, has_time), arrival)

    def _others_caught_up(self, header: int, end: int) -> bool:
        """Whether every other LiDAR has sent its part of the reference period (header stamp
        `header`, ending at `end`): its newest cloud has a header at or after the reference's (it
        started a period there, so its previous one is complete), or its period ends at `end`."""
        slack = MERGE_SLACK_S * NS_PER_S
        return all(
            (h is not None and h >= header) or e >= end - slack
            for h, e in zip(self._prev_header[1:], self._period_end[1:])
        )

    def _submit(self, scan: farlio.Scan, arrival: int) -> None:
        if self._last_scan_end is not None and scan.end_stamp_ns <= self._last_scan_end:
            self.report(
                "scans_out_of_order",
                f"scan ending {scan.end_stamp_ns} ns is not after the previous {self._last_scan_end} ns: dropped",
            )
            return
        removed = scan.remove_non_finite()
        if removed:
            self.report("points_non_finite", f"{self.topics[0]}: {removed} points with NaN/Inf dropped")
        if len(scan) == 0:
            self.report("clouds_empty", f"{self.topics[0]}: scan ending {scan.end_stamp_ns} ns has no point: dropped")
            return
        if not self._imu_ready(arrival):
            return
        if (
            self._last_imu_ns is not None
            and abs(scan.end_stamp_ns - self._last_imu_ns) > MAX_CLOCK_DIFFERENCE_S * NS_PER_S
        ):
            self.report(
                "scans_clock_mismatch",
                f"scan ending {scan.end_stamp_ns} ns is {(scan.end_stamp_ns - self._last_imu_ns) / NS_PER_S:+.3f} s "
                f"from the newest IMU stamp: unsynchronised clocks or a wrong time_offset_s",
            )
        self._last_scan_end = scan.end_stamp_ns
        self._arrivals[scan.end_stamp_ns] = arrival
        self.stats.scans += 1
        self.odometry.add_scan(scan, consume=True)  # moved in, not copied; a busy worker reports it as dropped

    def _imu_ready(self, arrival: int) -> bool:
        """Whether scans may go to the odometry: an IMU sample has come, or none is expected, or
        the wait for the first one is over (then LiDAR-only)."""
        if not self.params.uses_imu or self._last_imu_ns is not None or self._lidar_only_warned:
            return True
        if self._first_cloud_at is None:
            self._first_cloud_at = arrival
        if arrival - self._first_cloud_at < self.params.imu_wait_s * NS_PER_S:
            self.report("scans_before_imu", f"no IMU sample on {self.params.imu_topic} yet: scan dropped")
            return False
        self._warn_lidar_only(f"no IMU sample on {self.params.imu_topic} within imu_wait_s {self.params.imu_wait_s} s")
        return True

    # --- results and health ----------------------------------------------------------------------
    def wait_frames(self, timeout_s: float) -> list[FrameReport]:
        """The scans' results since the last call, waiting up to timeout_s for one (GIL released)."""
        frames = self.odometry.wait_frames(timeout_s)
        done = self.clock()
        return [FrameReport(f, self._arrivals.pop(f.scan.stamp_ns, done), done) for f in frames]

    def _seen_now(self, topic: str, now: int) -> None:
        self._last_seen[topic] = now
        self._seen.add(topic)

    def has_seen(self, topic: str) -> bool:
        """Whether a message came on `topic`."""
        return topic in self._seen

    def silent_topics(self) -> tuple[list[str], list[str]]:
        """(topics that fell silent, topics that resumed) since the last call."""
        now = self.clock()
        limit = self.params.silent_topic_timeout_s * NS_PER_S
        fell, resumed = [], []
        for topic, seen in self._last_seen.items():
            silent = now - seen > limit
            if silent and topic not in self._silent:
                self._silent.add(topic)
                self.stats.silent_topics += 1
                fell.append(topic)
            elif not silent and topic in self._silent:
                self._silent.discard(topic)
                resumed.append(topic)
        return fell, resumed

    def stop(self) -> None:
        """Finishes the scan in progress and ends the worker."""
        self.odometry.stop()
