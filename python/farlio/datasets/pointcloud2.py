"""sensor_msgs/PointCloud2 to numpy: the byte layout from the message's fields, and the per-point
time convention of the driver that wrote it.

Decoding is vectorised: one structured numpy dtype built from the fields (offsets, point_step,
endianness; padding bytes are simply not named), one `np.frombuffer`, no per-point Python.

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

from farlio import _core
from farlio._core import NS_PER_S

#: PointField datatype codes (sensor_msgs/PointField) -> numpy type
POINTFIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}
#: names of the per-point time field, first found wins
TIME_FIELDS = ("t", "time", "timestamp", "offset_time", "time_stamp", "time_offset", "ts")
INTENSITY_FIELDS = ("intensity", "reflectivity", "i")
#: nanoseconds per unit of a time field
NS_PER_UNIT = {"s": NS_PER_S, "ms": 1_000_000, "us": 1_000, "ns": 1}
TIME_UNITS = ("auto", *NS_PER_UNIT)
HEADER_STAMPS = ("auto", "start", "end")
#: time values (in s) above this are absolute (Unix) times, not offsets (1e6 s is 11.6 days)
ABSOLUTE_TIME_MIN_S = 1e6
#: a scan lasting longer than this means the time unit was misread (the limit of every loader)
MAX_SCAN_SPAN_S = _core.io.MAX_SCAN_SPAN_S
#: offsets within this of 0 still count as "<= 0" when deciding that the header is the scan end
HEADER_END_TOLERANCE_S = 1e-6
#: bytes of one point at most (drivers use tens; numpy's structured types end at 2^31)
MAX_POINT_STEP = 1 << 16


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


def cloud_dtype(msg: Any, where: str) -> np.dtype:
    """The structured dtype of one point: every field at its offset, itemsize point_step."""
    if not 0 < int(msg.point_step) <= MAX_POINT_STEP:
        raise CloudError(f"{where}: point_step {msg.point_step} is not in 1..{MAX_POINT_STEP} bytes")
    order = ">" if msg.is_bigendian else "<"
    names, formats, offsets = [], [], []
    for f in msg.fields:
        if f.datatype not in POINTFIELD_TYPES:
            raise CloudError(
                f"{where}: field '{f.name}' has datatype {f.datatype}; expected one of "
                f"{sorted(POINTFIELD_TYPES)} (sensor_msgs/PointField)"
            )
        base = np.dtype(order + POINTFIELD_TYPES[f.datatype])
        count = max(int(f.count), 1)
        if f.offset + base.itemsize * count > msg.point_step:
            raise CloudError(
                f"{where}: field '{f.name}' at offset {f.offset} ({count} x {base.itemsize} bytes) "
                f"extends past point_step {msg.point_step}"
            )
        if f.name in names:  # duplicate names (some drivers): keep the first
            continue
        names.append(f.name)
        formats.append(base if count == 1 else (base, (count,)))
        offsets.append(f.offset)
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": msg.point_step})


def structured_points(msg: Any, where: str) -> np.ndarray:
    """The message's points as a 1-D structured array (rows with padding at their ends handled)."""
    dtype = cloud_dtype(msg, where)
    n = int(msg.width) * int(msg.height)
    data = (
        np.ascontiguousarray(msg.data).view(np.uint8).reshape(-1)
        if isinstance(msg.data, np.ndarray)
        else np.frombuffer(msg.data, dtype=np.uint8)
    )
    row_bytes = int(msg.width) * int(msg.point_step)
    row_step = int(msg.row_step) or row_bytes
    if msg.height > 1 and row_step < row_bytes:
        raise CloudError(
            f"{where}: row_step {row_step} is shorter than a row of {msg.width} points of {msg.point_step} bytes"
        )
    needed = (int(msg.height) - 1) * row_step + row_bytes if n else 0
    if data.size < needed:
        raise CloudError(
            f"{where}: data holds {data.size} bytes but {msg.height} rows of {msg.width} points "
            f"need {needed} (row_step {row_step}, point_step {msg.point_step}; truncated?)"
        )
    if row_step == row_bytes or msg.height <= 1:
        return np.frombuffer(data[: n * msg.point_step], dtype=dtype)
    rows = np.lib.stride_tricks.as_strided(data, shape=(msg.height, row_bytes), strides=(row_step, 1))
    return np.frombuffer(np.ascontiguousarray(rows), dtype=dtype)


def _time_field(names: Sequence[str], options: TimeOptions, where: str) -> str | None:
    if options.field == "none":
        return None
    if options.field != "auto":
        if options.field not in names:
            raise CloudError(f"{where}: no time field '{options.field}' (fields: {', '.join(names)})")
        return options.field
    return next((n for n in TIME_FIELDS if n in names), None)


def _offsets_s(values: np.ndarray, header_ns: int, name: str, options: TimeOptions, where: str) -> np.ndarray:
    """Per-point offsets in s from the header stamp."""
    if values.dtype.kind not in "iuf":
        raise CloudError(f"{where}: time field '{name}' has type {values.dtype}; expected a number")
    unit = options.unit
    if unit == "auto":
        unit = "s" if values.dtype.kind == "f" else "ns"
    scale = NS_PER_UNIT[unit] / NS_PER_S
    if values.size == 0:
        return np.zeros(0)
    lo, hi = float(values.min()), float(values.max())
    if lo * scale > ABSOLUTE_TIME_MIN_S:
        # absolute times: subtract the header in float64 seconds (precision ~0.2 us for Unix times)
        offsets = values.astype(np.float64) * scale - header_ns / NS_PER_S
        if values.dtype.kind != "f":
            offsets = (values.astype(np.int64) * NS_PER_UNIT[unit] - header_ns) / NS_PER_S
    else:
        offsets = values.astype(np.float64) * scale
    span = (hi - lo) * scale
    if not _core.io.point_time_span_plausible(span):
        raise CloudError(
            f"{where}: time field '{name}' ({values.dtype}) spans {hi - lo:g} raw units, which in "
            f"{unit} is {span:g} s, longer than a scan can last ({MAX_SCAN_SPAN_S:g} s): unknown time "
            f"unit; pass the unit explicitly (--time-unit one of {', '.join(NS_PER_UNIT)}) or "
            f"--time-field none"
        )
    return offsets


def decode(msg: Any, where: str, options: TimeOptions | None = None) -> Cloud:
    """Decodes a sensor_msgs/PointCloud2 (as deserialised by rosbags or any object with the same
    attributes). Points at the origin (no return) are dropped. Raises CloudError naming `where`."""
    options = options or TimeOptions()
    names = field_names(msg)
    missing = [c for c in "xyz" if c not in names]
    if missing:
        raise CloudError(
            f"{where}: PointCloud2 has no field {', '.join(repr(m) for m in missing)} "
            f"(fields: {', '.join(names) or 'none'}); expected x, y, z"
        )
    pts = structured_points(msg, where)
    xyz = np.empty((len(pts), 3), dtype=np.float32)
    for k, c in enumerate("xyz"):
        if pts.dtype[c].shape:
            raise CloudError(f"{where}: field '{c}' has count {pts.dtype[c].shape[0]}; expected 1")
        xyz[:, k] = pts[c]
    origin = (xyz[:, 0] == 0.0) & (xyz[:, 1] == 0.0) & (xyz[:, 2] == 0.0)  # no return
    keep = np.flatnonzero(~origin) if origin.any() else slice(None)
    xyz = xyz[keep]
    header_ns = stamp_ns(msg.header)
    inten_name = next((n for n in INTENSITY_FIELDS if n in names and not pts.dtype[n].shape), None)
    intensity = pts[inten_name][keep].astype(np.float32) if inten_name else None
    tname = _time_field(names, options, where)
    offsets = None
    header_is_end = options.header_stamp == "end"
    if tname is not None:
        if pts.dtype[tname].shape:
            raise CloudError(f"{where}: time field '{tname}' has count {pts.dtype[tname].shape[0]}; expected 1")
        offsets = _offsets_s(pts[tname][keep], header_ns, tname, options, where)
        if offsets.size:
            lo, hi = float(offsets.min()), float(offsets.max())
            if options.header_stamp == "auto":
                header_is_end = hi <= HEADER_END_TOLERANCE_S and lo < -HEADER_END_TOLERANCE_S
            elif header_is_end and lo >= 0.0:
                offsets = offsets - hi  # offsets from the start, header at the end: end = last point
            elif not header_is_end and hi <= 0.0:
                offsets = offsets - lo
    return Cloud(header_ns, xyz, intensity, offsets, header_is_end, str(getattr(msg.header, "frame_id", "")))


def time_field_of(msg: Any, options: TimeOptions | None = None) -> str | None:
    """The name of the time field `decode` would use (None: no per-point time)."""
    options = options or TimeOptions()
    return _time_field(field_names(msg), options, "cloud")
