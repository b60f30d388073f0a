"""sensor_msgs/PointCloud2 to numpy: the byte layout from the message's fields, and the per-point
time convention of the driver that wrote it.

Decoding: the rules (which field is the time, its unit, whether the header stamp is the scan start
or end) are here; the bytes are read by C++ (farlio._core.io.decode_pointcloud2: any PointField
datatype, either byte order, padding in points and rows) in one pass per field, straight into the
arrays of the Cloud. The bag loader and the ROS 2 node both decode with `decode`.

Per-point time conventions found in the wild (all handled by `TimeOptions` 'auto'):

| driver    | field         | type     | unit | origin                                       |
|-----------|---------------|----------|------|----------------------------------------------|
| Ouster    | `t`           | uint32   | ns   | relative to the header stamp (scan start)    |
| Velodyne  | `time`        | float32  | s    | relative to the header stamp (start or end)  |
| Hesai     | `timestamp`   | float64  | s    | absolute (Unix time)                         |
| Robosense | `timestamp`   | float64  | s    | absolute (Unix time)                         |
| Livox     | `offset_time` | uint32   | ns   | relative to the header stamp (scan start)    |

'auto' reads float fields as seconds and integer fields as nanoseconds; values above
ABSOLUTE_TIME_MIN_S seconds are absolute times, others are offsets from the header stamp.
Offsets that are all <= 0 mean that the header stamp is the scan END (Velodyne's newer drivers).
A time span longer than MAX_SCAN_SPAN_S is rejected as an unknown unit, naming the field (the rule
is the C++ one every loader uses: farlio._core.io.point_time_span_plausible, docs/io.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from farlio._core import NS_PER_S, InputError
from farlio._core import io as _io

#: PointField datatype codes (sensor_msgs/PointField) -> numpy type
POINTFIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}
#: the floating-point datatypes (their time values are read as s by the 'auto' unit)
FLOAT_DATATYPES = (7, 8)
#: names of the per-point time field, first found wins
TIME_FIELDS = ("t", "time", "timestamp", "offset_time", "time_stamp", "time_offset", "ts")
INTENSITY_FIELDS = ("intensity", "reflectivity", "i")
#: nanoseconds per unit of a time field
NS_PER_UNIT = {"s": NS_PER_S, "ms": 1_000_000, "us": 1_000, "ns": 1}
TIME_UNITS = ("auto", *NS_PER_UNIT)
HEADER_STAMPS = ("auto", "start", "end")
#: time values (in s) above this are absolute (Unix) times, not offsets (1e6 s is 11.6 days)
ABSOLUTE_TIME_MIN_S = 1e6
#: a scan lasting longer than this means the time unit was misread
MAX_SCAN_SPAN_S = _io.MAX_SCAN_SPAN_S
#: offsets within this of 0 still count as "<= 0" when deciding that the header is the scan end
HEADER_END_TOLERANCE_S = 1e-6


class CloudError(ValueError):
    """A PointCloud2 that cannot be decoded; the message names the topic/message and the field."""


@dataclass
class TimeOptions:
    """How to read per-point times: field name ('auto', or 'none' for no time), unit, and whether
    the header stamp is the scan start or end."""

    field: str = "auto"
    unit: str = "auto"
    header_stamp: str = "auto"

    def __post_init__(self) -> None:
        if self.unit not in TIME_UNITS:
            raise ValueError(f"unknown time unit '{self.unit}'; expected one of {', '.join(TIME_UNITS)}")
        if self.header_stamp not in HEADER_STAMPS:
            raise ValueError(
                f"unknown header stamp meaning '{self.header_stamp}'; expected one of {', '.join(HEADER_STAMPS)}"
            )


@dataclass
class Cloud:
    """A decoded cloud: points (N, 3) float32 in the sensor frame, intensity (N,) float32 or None,
    and per-point times as offsets in s from `stamp_ns` (None: no time field). `header_is_end`
    says whether `stamp_ns` is the end of the scan (else its start)."""

    stamp_ns: int
    points: np.ndarray
    intensity: np.ndarray | None
    offset_s: np.ndarray | None
    header_is_end: bool
    frame_id: str = ""

    def absolute_ns(self) -> np.ndarray:
        """Per-point absolute times (int64 ns); the stamp when there are no times."""
        if self.offset_s is None:
            return np.full(len(self.points), self.stamp_ns, dtype=np.int64)
        return self.stamp_ns + np.round(self.offset_s * NS_PER_S).astype(np.int64)


def stamp_ns(header: Any) -> int:
    """A std_msgs/Header stamp in ns (rosbags names ROS 1 and ROS 2 times sec/nanosec)."""
    return int(header.stamp.sec) * NS_PER_S + int(header.stamp.nanosec)


def field_names(msg: Any) -> list[str]:
    return [f.name for f in msg.fields]


def _time_field(names: Sequence[str], options: TimeOptions, where: str) -> str | None:
    if options.field == "none":
        return None
    if options.field != "auto":
        if options.field not in names:
            raise CloudError(f"{where}: no time field '{options.field}' (fields: {', '.join(names)})")
        return options.field
    return next((n for n in TIME_FIELDS if n in names), None)


def _data(msg: Any) -> np.ndarray:
    """The message's data as a 1-D uint8 array, without a copy for a uint8 array (rosbags), an
    array.array (rclpy) or bytes."""
    if isinstance(msg.data, np.ndarray):
        return np.ascontiguousarray(msg.data).view(np.uint8).reshape(-1)
    try:
        return np.frombuffer(msg.data, dtype=np.uint8)
    except TypeError:  # a list of ints
        return np.asarray(msg.data, dtype=np.uint8)


def _check_span(points: Any, name: str, datatype: int, unit: str, where: str) -> None:
    """A scan lasts at most MAX_SCAN_SPAN_S: a longer span of the time field means a wrong unit."""
    lo, hi = points.time_min, points.time_max
    span = (hi - lo) * NS_PER_UNIT[unit] / NS_PER_S
    if not _io.point_time_span_plausible(span):
        raise CloudError(
            f"{where}: time field '{name}' ({np.dtype(POINTFIELD_TYPES[datatype]).name}) spans {hi - lo:g} raw "
            f"units, which in {unit} is {span:g} s, longer than a scan can last ({MAX_SCAN_SPAN_S:g} s): unknown "
            f"time unit; pass the unit explicitly (--time-unit one of {', '.join(NS_PER_UNIT)}) or "
            f"--time-field none"
        )


def decode(msg: Any, where: str, options: TimeOptions | None = None) -> Cloud:
    """Decodes a sensor_msgs/PointCloud2 (as deserialised by rosbags or rclpy, or any object with the
    same attributes). Points at the origin (no return) are dropped. Raises CloudError naming `where`.

    The fields, the time unit and the header stamp's meaning are chosen here; the bytes are read in
    one C++ pass (farlio._core.io.decode_pointcloud2), the arrays are views of its result."""
    options = options or TimeOptions()
    names = field_names(msg)
    fields = [(str(f.name), int(f.offset), int(f.datatype), int(f.count)) for f in msg.fields]
    first: dict[str, tuple[int, int]] = {}  # name -> (datatype, count) of its first field
    for name, _, datatype, count in fields:
        first.setdefault(name, (datatype, count))
    tname = _time_field(names, options, where)
    inten_name = next((n for n in INTENSITY_FIELDS if n in first and first[n][1] <= 1), None)
    unit = options.unit
    if unit == "auto":
        unit = "s" if tname is not None and first[tname][0] in FLOAT_DATATYPES else "ns"
    header_ns = stamp_ns(msg.header)
    try:
        d = _io.decode_pointcloud2(
            _data(msg),
            width=int(msg.width),
            height=int(msg.height),
            point_step=int(msg.point_step),
            row_step=int(msg.row_step),
            big_endian=bool(msg.is_bigendian),
            fields=fields,
            intensity_field=inten_name or "",
            time_field=tname or "",
            time_ns_per_unit=NS_PER_UNIT[unit],
            header_ns=header_ns,
            header_s=header_ns / NS_PER_S,
            absolute_time_min_s=ABSOLUTE_TIME_MIN_S,
            where=where,
        )
    except InputError as e:
        raise CloudError(str(e)) from None
    offsets = None
    header_is_end = options.header_stamp == "end"
    if tname is not None:
        offsets = d.offset_s
        if offsets.size:
            _check_span(d, tname, first[tname][0], unit, where)
            lo, hi = d.offset_min_s, d.offset_max_s
            if options.header_stamp == "auto":
                header_is_end = hi <= HEADER_END_TOLERANCE_S and lo < -HEADER_END_TOLERANCE_S
            elif header_is_end and lo >= 0.0:
                offsets = offsets - hi  # offsets from the start, header at the end: end = last point
            elif not header_is_end and hi <= 0.0:
                offsets = offsets - lo
    intensity = d.intensity if inten_name else None
    return Cloud(header_ns, d.points, intensity, offsets, header_is_end, str(getattr(msg.header, "frame_id", "")))


def time_field_of(msg: Any, options: TimeOptions | None = None) -> str | None:
    """The name of the time field `decode` would use (None: no per-point time)."""
    options = options or TimeOptions()
    return _time_field(field_names(msg), options, "cloud")
