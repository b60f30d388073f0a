"""numpy to sensor_msgs/PointCloud2 bytes, with the per-point time convention of a chosen driver:
the inverse of pointcloud2.decode. Used by the bag writer (rosbag_write.py) and the ROS 2 player
(farlio.ros2.play), which wrap the result in their own message types.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from farlio._core import NS_PER_S

#: sensor_msgs/PointField datatype codes
FLOAT32, FLOAT64, UINT32 = 7, 8, 6
POINTFIELD_CODES = {"f4": FLOAT32, "f8": FLOAT64, "u4": UINT32}


@dataclass(frozen=True)
class TimeConvention:
    """How a driver writes per-point times: field name, numpy type, unit (ns per unit), whether
    values are absolute times, and whether the header stamp is the scan end."""

    field: str | None
    dtype: str
    ns_per_unit: int
    absolute: bool
    header_is_end: bool


CONVENTIONS = {
    "ouster": TimeConvention("t", "u4", 1, False, False),
    "velodyne": TimeConvention("time", "f4", NS_PER_S, False, True),
    "hesai": TimeConvention("timestamp", "f8", NS_PER_S, True, False),
    "livox": TimeConvention("offset_time", "u4", 1, False, False),
    "robosense": TimeConvention("timestamp", "f8", NS_PER_S, True, True),
    "none": TimeConvention(None, "", 0, False, False),
}


@dataclass
class EncodedCloud:
    """The parts of a PointCloud2 (height 1, little endian): header stamp, fields as (name,
    offset, datatype code), point step and the point bytes."""

    header_ns: int
    fields: list[tuple[str, int, int]]
    point_step: int
    data: np.ndarray  # uint8, len = point_step * number of points

    @property
    def width(self) -> int:
        return len(self.data) // self.point_step if self.point_step else 0


def encode(
    points: np.ndarray,
    time_s: np.ndarray | None,
    intensity: np.ndarray | None,
    start_ns: int,
    end_ns: int,
    convention: str = "ouster",
    padding: int = 0,
) -> EncodedCloud:
    """The cloud of a scan [start_ns, end_ns]: points (N, 3), time_s per-point time in s since
    start_ns (None: no time field), intensity (N,) or None. `padding` bytes are left unnamed at the
    end of every point (as drivers do for alignment)."""
    if convention not in CONVENTIONS:
        raise ValueError(f"unknown time convention '{convention}'; expected one of {', '.join(CONVENTIONS)}")
    conv = CONVENTIONS[convention]
    header_ns = end_ns if conv.header_is_end else start_ns
    names = [("x", "f4"), ("y", "f4"), ("z", "f4")]
    if intensity is not None:
        names.append(("intensity", "f4"))
    if conv.field is not None and time_s is not None:
        names.append((conv.field, conv.dtype))
    offsets, off = [], 0
    for _, t in names:
        offsets.append(off)
        off += np.dtype(t).itemsize
    dtype = np.dtype(
        {
            "names": [n for n, _ in names],
            "formats": [t for _, t in names],
            "offsets": offsets,
            "itemsize": off + padding,
        }
    )
    fields = [(n, o, POINTFIELD_CODES[t]) for (n, t), o in zip(names, offsets)]
    if len(names) == len("xyz") and not padding:  # x, y, z only: the bytes of the (N, 3) float32 points
        data = np.ascontiguousarray(points, dtype=np.float32).view(np.uint8).reshape(-1)
        return EncodedCloud(header_ns, fields, dtype.itemsize, data)
    arr = np.zeros(len(points), dtype=dtype)
    for k, c in enumerate("xyz"):
        arr[c] = points[:, k]
    if intensity is not None:
        arr["intensity"] = intensity
    if conv.field is not None and time_s is not None:
        t = np.asarray(time_s, dtype=np.float64)
        if conv.absolute:
            arr[conv.field] = (start_ns + np.round(t * NS_PER_S)) / conv.ns_per_unit
        else:
            rel_ns = np.round(t * NS_PER_S) + (start_ns - header_ns)
            arr[conv.field] = rel_ns / conv.ns_per_unit if conv.ns_per_unit > 1 else np.round(rel_ns)
    return EncodedCloud(header_ns, fields, dtype.itemsize, arr.view(np.uint8).reshape(-1))
