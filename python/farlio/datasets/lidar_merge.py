"""Decoded PointCloud2 messages into scans: the scan interval of a cloud, and several LiDARs merged
into one scan per period of the first. Shared by the bag loader (rosbag.py) and the ROS 2 node
(farlio.ros2), so that a live robot and `farlio run` on its bag make the same scans.

Merging: the points of the other LiDARs whose times fall into the reference LiDAR's period are
moved into its frame with their extrinsics; each point keeps its own time and gets a sensor id
(the index of its LiDAR).
"""

from __future__ import annotations

from collections import deque

import numpy as np

import farlio
from farlio._core import NS_PER_S

from .folders import DEFAULT_PERIOD_NS
from .pointcloud2 import MAX_SCAN_SPAN_S, Cloud

MAX_SCAN_SPAN_NS = int(MAX_SCAN_SPAN_S * NS_PER_S)

#: clouds of one of the other LiDARs, each with its per-point absolute times (ns), oldest first
TimedClouds = deque[tuple[Cloud, np.ndarray]]


def scan_interval(cur: Cloud, nxt: Cloud | None, prev: tuple[int, int] | None) -> tuple[int, int]:
    """Scan start and end (ns) of the reference cloud `cur`: the header stamp is one of them, the
    neighbouring header (the next cloud `nxt` when known, else the previous interval `prev`, else
    the per-point times) gives the other."""

    def plausible(d: int) -> bool:
        return 0 < d <= MAX_SCAN_SPAN_NS

    prev_period = prev[1] - prev[0] if prev else None
    next_period = nxt.stamp_ns - cur.stamp_ns if nxt is not None and plausible(nxt.stamp_ns - cur.stamp_ns) else None
    offsets = cur.offset_s
    if cur.header_is_end:
        end = cur.stamp_ns
        if prev is not None and plausible(end - prev[1]):
            return prev[1], end
        period = (
            next_period
            or prev_period
            or (int(round(-offsets.min() * NS_PER_S)) if offsets is not None and offsets.size else DEFAULT_PERIOD_NS)
        )
        return end - period, end
    start = cur.stamp_ns
    period = (
        next_period
        or prev_period
        or (int(round(offsets.max() * NS_PER_S)) if offsets is not None and offsets.size else DEFAULT_PERIOD_NS)
    )
    return start, start + max(period, 1)


def live_interval(cur: Cloud, prev_header_ns: int | None) -> tuple[int, int]:
    """Scan start and end of `cur` when the next cloud is not known yet (live): the gap from the
    previous header stamp is the period (exact for a LiDAR at a constant rate); without a plausible
    one, as scan_interval does for a lone cloud."""
    gap = cur.stamp_ns - prev_header_ns if prev_header_ns is not None else 0
    if not 0 < gap <= MAX_SCAN_SPAN_NS:
        return scan_interval(cur, None, None)
    return (cur.stamp_ns - gap, cur.stamp_ns) if cur.header_is_end else (cur.stamp_ns, cur.stamp_ns + gap)


def caught_up(others: list[TimedClouds], end: int) -> bool:
    """Whether every other LiDAR has delivered points at or after `end` (its clouds for the period
    ending there are complete)."""
    return all(q and q[-1][1].max(initial=0) >= end for q in others)


def assemble(
    cur: Cloud,
    start: int,
    end: int,
    others: list[TimedClouds],
    extrinsics: list[farlio.SE3],
    has_time: bool,
) -> farlio.Scan:
    """The scan [start, end) of the reference cloud `cur` with the points of the other LiDARs'
    clouds that fall into it, in the reference frame (extrinsics: T_imu_lidar of every LiDAR, the
    reference first). Clouds of the others that end before `end` are consumed (popped). Per-point
    times are kept when `has_time` and every part has them."""
    shift_s = (cur.stamp_ns - start) / NS_PER_S
    pts = [cur.points]
    times = [None if cur.offset_s is None else cur.offset_s + shift_s]
    inten = [cur.intensity if cur.intensity is not None else np.zeros(len(cur.points), np.float32)]
    ids = [np.zeros(len(cur.points), np.uint8)]
    T_lidar_imu = extrinsics[0].inverse()
    for k, q in enumerate(others, start=1):
        m = (T_lidar_imu * extrinsics[k]).matrix()
        for cloud, abs_ns in q:
            sel = (abs_ns >= start) & (abs_ns < end)
            if not sel.any():
                continue
            pts.append(cloud.points[sel] @ m[:3, :3].T.astype(np.float32) + m[:3, 3].astype(np.float32))
            times.append((abs_ns[sel] - start) / NS_PER_S)
            inten.append(cloud.intensity[sel] if cloud.intensity is not None else np.zeros(int(sel.sum()), np.float32))
            ids.append(np.full(int(sel.sum()), k, np.uint8))
        while q and q[0][1].max(initial=0) < end:
            q.popleft()

    def joined(parts: list[np.ndarray]) -> np.ndarray:
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    points = np.ascontiguousarray(joined(pts), dtype=np.float32)
    time_s = joined(times).astype(np.float32) if has_time and all(t is not None for t in times) else None
    return farlio.Scan(
        points,
        time_s=time_s,
        intensity=np.ascontiguousarray(joined(inten), dtype=np.float32),
        start_stamp_ns=start,
        end_stamp_ns=end,
        sensor_id=np.concatenate(ids) if len(extrinsics) > 1 else None,
    )
