"""PointCloud2 decoding without a bag: layouts (padding, big endian, row padding, COUNT) and the
per-point time conventions of Ouster, Velodyne, Hesai, Livox and Robosense."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("farlio._core")

from farlio.datasets.pointcloud2 import CloudError, TimeOptions, decode  # noqa: E402

POINTS = 64
HEADER_NS = 1_700_000_000_123_456_789
PERIOD_S = 0.1
CODES = {"i1": 1, "u1": 2, "i2": 3, "u2": 4, "i4": 5, "u4": 6, "f4": 7, "f8": 8}


def message(
    fields: list[tuple[str, str]],
    values: dict[str, np.ndarray],
    *,
    big_endian: bool = False,
    padding: int = 0,
    height: int = 1,
    row_padding: int = 0,
    stamp_ns: int = HEADER_NS,
):
    """A PointCloud2-like object holding `values` in the layout the fields describe."""
    order = ">" if big_endian else "<"
    offsets, off = [], 0
    for _, t in fields:
        offsets.append(off)
        off += np.dtype(t).itemsize
    dtype = np.dtype(
        {
            "names": [n for n, _ in fields],
            "formats": [order + t for _, t in fields],
            "offsets": offsets,
            "itemsize": off + padding,
        }
    )
    n = len(next(iter(values.values())))
    arr = np.zeros(n, dtype=dtype)
    for name, v in values.items():
        arr[name] = v
    width = n // height
    rows = arr.view(np.uint8).reshape(height, width * dtype.itemsize)
    data = np.concatenate([rows, np.full((height, row_padding), 0xAB, np.uint8)], axis=1).reshape(-1)
    header = SimpleNamespace(stamp=SimpleNamespace(sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9), frame_id="os")
    pfields = [SimpleNamespace(name=nm, offset=o, datatype=CODES[t], count=1) for (nm, t), o in zip(fields, offsets)]
    return SimpleNamespace(
        header=header,
        height=height,
        width=width,
        fields=pfields,
        is_bigendian=big_endian,
        point_step=dtype.itemsize,
        row_step=width * dtype.itemsize + row_padding,
        data=data,
    )


@pytest.fixture
def cloud():
    rng = np.random.default_rng(7)
    xyz = rng.uniform(-30, 30, (POINTS, 3)).astype(np.float32)
    t = np.sort(rng.uniform(0.0, PERIOD_S, POINTS))
    return xyz, t


def xyz_values(xyz):
    return {"x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2]}


@pytest.mark.parametrize("big_endian,padding,height,row_padding", [(False, 0, 1, 0), (True, 5, 1, 0), (False, 2, 4, 7)])
def test_layouts(cloud, big_endian, padding, height, row_padding):
    xyz, _ = cloud
    inten = np.arange(POINTS, dtype=np.float32)
    msg = message(
        [("x", "f4"), ("y", "f4"), ("z", "f4"), ("intensity", "f4")],
        {**xyz_values(xyz), "intensity": inten},
        big_endian=big_endian,
        padding=padding,
        height=height,
        row_padding=row_padding,
    )
    c = decode(msg, "test")
    np.testing.assert_array_equal(c.points, xyz)
    np.testing.assert_array_equal(c.intensity, inten)
    assert c.offset_s is None and c.stamp_ns == HEADER_NS


@pytest.mark.parametrize(
    "driver,field,dtype,to_raw,header_is_end",
    [
        ("ouster", "t", "u4", lambda t, s: np.round(t * 1e9), False),
        ("velodyne", "time", "f4", lambda t, s: t - PERIOD_S, True),
        ("hesai", "timestamp", "f8", lambda t, s: s / 1e9 + t, False),
        ("livox", "offset_time", "u4", lambda t, s: np.round(t * 1e9), False),
        ("robosense", "timestamp", "f8", lambda t, s: s / 1e9 - PERIOD_S + t, True),
    ],
)
def test_time_conventions(cloud, driver, field, dtype, to_raw, header_is_end):
    """Times written in the driver's convention decode to the same absolute point times."""
    xyz, t = cloud
    stamp = HEADER_NS
    msg = message([("x", "f4"), ("y", "f4"), ("z", "f4"), (field, dtype)], {**xyz_values(xyz), field: to_raw(t, stamp)})
    c = decode(msg, driver)
    start = stamp - (round(PERIOD_S * 1e9) if header_is_end else 0)
    expected_ns = start + np.round(t * 1e9).astype(np.int64)
    # float32 offsets of 0.1 s: ~10 ns; float64 Unix seconds: ~0.2 us
    tolerance_ns = 500 if dtype == "f8" else 20
    assert np.abs(c.absolute_ns() - expected_ns).max() <= tolerance_ns
    if driver in ("ouster", "livox", "velodyne"):  # relative conventions: the header's meaning is visible
        assert c.header_is_end == header_is_end


def test_explicit_unit_and_header_end(cloud):
    xyz, t = cloud
    msg = message([("x", "f4"), ("y", "f4"), ("z", "f4"), ("t", "u4")], {**xyz_values(xyz), "t": np.round(t * 1e6)})
    c = decode(msg, "us", TimeOptions(unit="us", header_stamp="end"))
    assert c.header_is_end
    np.testing.assert_allclose(c.offset_s, t - t.max(), atol=1e-6)


def test_errors_name_the_message_and_field(cloud):
    xyz, t = cloud
    with pytest.raises(CloudError, match=r"/lidar msg 3: PointCloud2 has no field 'z' \(fields: x, y, t\)"):
        decode(
            message([("x", "f4"), ("y", "f4"), ("t", "f4")], {"x": xyz[:, 0], "y": xyz[:, 1], "t": t}), "/lidar msg 3"
        )
    msg = message([("x", "f4"), ("y", "f4"), ("z", "f4"), ("t", "u4")], {**xyz_values(xyz), "t": np.round(t * 1e9)})
    with pytest.raises(CloudError, match=r"time field 't' \(uint32\).*in s is .* unknown time unit"):
        decode(msg, "m", TimeOptions(unit="s"))
    with pytest.raises(CloudError, match=r"no time field 'stamp' \(fields: x, y, z, t\)"):
        decode(msg, "m", TimeOptions(field="stamp"))
    msg.data = msg.data[: len(msg.data) // 2]
    with pytest.raises(CloudError, match=r"m: data holds \d+ bytes but .* truncated"):
        decode(msg, "m")
    with pytest.raises(ValueError, match="unknown time unit 'min'"):
        TimeOptions(unit="min")
