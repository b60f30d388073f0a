"""The numpy PointCloud2 decoder that farlio.datasets.pointcloud2.decode used before the C++ one
(kept verbatim as the oracle of tests/python/test_pointcloud2.py, not used by farlio): one
structured dtype built from the fields, np.frombuffer, per-field numpy gathers."""

from __future__ import annotations

from typing import Any

import numpy as np
from farlio.datasets.pointcloud2 import (
    ABSOLUTE_TIME_MIN_S,
    HEADER_END_TOLERANCE_S,
    INTENSITY_FIELDS,
    MAX_SCAN_SPAN_S,
    NS_PER_S,
    NS_PER_UNIT,
    POINTFIELD_TYPES,
    Cloud,
    CloudError,
    TimeOptions,
    _time_field,
    field_names,
    stamp_ns,
)


def cloud_dtype(msg: Any, where: str) -> np.dtype:
    """The structured dtype of one point: every field at its offset, itemsize point_step."""
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
    if not np.isfinite(span) or span > MAX_SCAN_SPAN_S:
        raise CloudError(
            f"{where}: time field '{name}' ({values.dtype}) spans {hi - lo:g} raw units, which in "
            f"{unit} is {span:g} s, longer than a scan can last ({MAX_SCAN_SPAN_S:g} s): unknown time "
            f"unit; pass the unit explicitly (--time-unit one of {', '.join(NS_PER_UNIT)}) or "
            f"--time-field none"
        )
    return offsets


def reference_decode(msg: Any, where: str, options: TimeOptions | None = None) -> Cloud:
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
