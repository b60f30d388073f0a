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


# --- the C++ decoder against the numpy decoder it replaced (pointcloud2_reference.py) ------------

NAN = float("nan")


def decoded_equal(a, b, absolute_float_time: bool = False) -> None:
    """Two decoded clouds are the same: points and intensities exactly (NaN points included),
    offsets exactly, or within 1 us for absolute float times, where a CPU with fused multiply-add
    may round v * unit - header once instead of twice (1 ulp of a Unix time in s is 0.24 us)."""
    assert (a.stamp_ns, a.header_is_end, a.frame_id) == (b.stamp_ns, b.header_is_end, b.frame_id)
    assert a.points.dtype == b.points.dtype == np.float32 and a.points.shape == b.points.shape
    np.testing.assert_array_equal(a.points, b.points)
    assert (a.intensity is None) == (b.intensity is None)
    if a.intensity is not None:
        assert a.intensity.dtype == b.intensity.dtype == np.float32
        np.testing.assert_array_equal(a.intensity, b.intensity)
    assert (a.offset_s is None) == (b.offset_s is None)
    if a.offset_s is not None:
        assert a.offset_s.dtype == b.offset_s.dtype == np.float64
        if absolute_float_time:
            np.testing.assert_allclose(a.offset_s, b.offset_s, rtol=0, atol=1e-6)
        else:
            np.testing.assert_array_equal(a.offset_s, b.offset_s)


def varied_cloud(xyz_types, extra, n=POINTS, seed=3, **layout):
    """A message with x, y, z of the given types, the `extra` fields [(name, type, values)], a few
    points at the origin (no return) and a NaN point."""
    rng = np.random.default_rng(seed)
    xyz = rng.uniform(-30, 30, (n, 3))
    if any(t[0] in "iu" for t in xyz_types):
        xyz = np.round(xyz)
    xyz[[1, 7]] = 0.0  # no return: dropped
    xyz[4] = [NAN, 1.0, 2.0] if all(t[0] == "f" for t in xyz_types) else xyz[4]  # NaN: kept
    fields = [(c, t) for c, t in zip("xyz", xyz_types)] + [(name, t) for name, t, _ in extra]
    values = {**{c: xyz[:, k] for k, c in enumerate("xyz")}, **{name: v for name, _, v in extra}}
    return message(fields, values, **layout)


TIME_CASES = {
    # name: (field, type, raw values from t in [0, PERIOD_S) and the header stamp, TimeOptions, absolute float)
    "ouster_u4_ns": ("t", "u4", lambda t, s: np.round(t * 1e9), TimeOptions(), False),
    "velodyne_f4_s_end": ("time", "f4", lambda t, s: t - PERIOD_S, TimeOptions(), False),
    "hesai_f8_unix_s": ("timestamp", "f8", lambda t, s: s / 1e9 + t, TimeOptions(), True),
    "livox_u4_ns": ("offset_time", "u4", lambda t, s: np.round(t * 1e9), TimeOptions(), False),
    "i4_us": ("ts", "i4", lambda t, s: np.round(t * 1e6), TimeOptions(unit="us"), False),
    "f8_ms_header_end": ("time", "f8", lambda t, s: t * 1e3, TimeOptions(unit="ms", header_stamp="end"), False),
    "u4_ns_header_start_negative": (
        "t",
        "i4",
        lambda t, s: np.round((t - PERIOD_S) * 1e9),
        TimeOptions(header_stamp="start"),
        False,
    ),
    "u4_unix_s": ("time_stamp", "u4", lambda t, s: s // 10**9 + np.round(t * 10), TimeOptions(unit="s"), False),
    "f8_unix_ms": ("timestamp", "f8", lambda t, s: s / 1e6 + t * 1e3, TimeOptions(unit="ms"), True),
    "u2_named_field": ("stamp", "u2", lambda t, s: np.round(t * 1e5), TimeOptions(field="stamp", unit="us"), False),
    "none": ("t", "u4", lambda t, s: np.round(t * 1e9), TimeOptions(field="none"), False),
}


@pytest.mark.parametrize("xyz_types", [("f4",) * 3, ("f8",) * 3, ("f8", "f4", "i2")], ids=["f4", "f8", "mixed"])
@pytest.mark.parametrize("case", sorted(TIME_CASES))
@pytest.mark.parametrize(
    "layout",
    [{}, {"big_endian": True, "padding": 3}, {"padding": 2, "height": 4, "row_padding": 5}],
    ids=["packed", "big_endian_padded", "rows_padded"],
)
def test_cpp_decode_equals_the_numpy_decoder(cloud, xyz_types, case, layout):
    from pointcloud2_reference import reference_decode

    _, t = cloud
    field, dtype, to_raw, options, absolute_float = TIME_CASES[case]
    intensity = ("reflectivity", "u2", np.arange(POINTS) * 3)
    msg = varied_cloud(xyz_types, [intensity, (field, dtype, to_raw(t, HEADER_NS))], **layout)
    new, old = decode(msg, "m", options), reference_decode(msg, "m", options)
    decoded_equal(new, old, absolute_float)
    assert len(new.points) == POINTS - 2
    assert (new.offset_s is None) == (case == "none")


@pytest.mark.parametrize("kind", ["numpy", "bytes", "array", "int8_numpy"])
def test_every_kind_of_data_buffer(cloud, kind):
    """rosbags gives a uint8 numpy array, rclpy an array.array('B'); bytes and other numpy views work too."""
    import array

    from pointcloud2_reference import reference_decode

    xyz, t = cloud
    msg = message([("x", "f4"), ("y", "f4"), ("z", "f4"), ("t", "u4")], {**xyz_values(xyz), "t": np.round(t * 1e9)})
    raw = msg.data.tobytes()
    msg.data = {
        "numpy": msg.data,
        "bytes": raw,
        "array": array.array("B", raw),
        "int8_numpy": np.frombuffer(raw, np.int8),
    }[kind]
    decoded_equal(decode(msg, "m"), reference_decode(msg, "m"))


def test_intensity_candidates_and_duplicate_fields(cloud):
    """An intensity field with a count is skipped for the next candidate; a repeated name means its
    first field, in both decoders."""
    from pointcloud2_reference import reference_decode

    xyz, _ = cloud
    msg = message(
        [("x", "f4"), ("y", "f4"), ("z", "f4"), ("intensity", "u1"), ("i", "f8"), ("x_again", "f4")],
        {
            **xyz_values(xyz),
            "intensity": np.arange(POINTS) % 200,
            "i": np.linspace(0, 1, POINTS),
            "x_again": np.full(POINTS, 5.0),
        },
    )
    msg.fields[3].count = 2  # intensity as two values (overlapping i): not a scalar, so i is the intensity
    msg.fields[5].name = "x"  # a second x: the first one is the coordinate
    new, old = decode(msg, "m"), reference_decode(msg, "m")
    decoded_equal(new, old)
    np.testing.assert_array_equal(new.points, xyz)
    np.testing.assert_array_equal(new.intensity, np.linspace(0, 1, POINTS).astype(np.float32))


@pytest.mark.parametrize(
    "change",
    [
        "no_z",
        "no_fields",
        "datatype_9",
        "past_point_step",
        "count_x",
        "count_time",
        "truncated",
        "unit_s_for_ns",
        "nan_time",
        "missing_named_time",
    ],
)
def test_errors_are_those_of_the_numpy_decoder(cloud, change):
    from pointcloud2_reference import reference_decode

    xyz, t = cloud
    fields = [("x", "f4"), ("y", "f4"), ("z", "f4"), ("t", "u4"), ("time", "f4")]
    times = t.copy()
    if change == "nan_time":
        times[5] = NAN
    msg = message(fields, {**xyz_values(xyz), "t": np.round(t * 1e9), "time": times}, padding=8)
    options = TimeOptions()
    if change == "no_z":
        msg.fields = [f for f in msg.fields if f.name != "z"]
    elif change == "no_fields":
        msg.fields = []
    elif change == "datatype_9":
        msg.fields[4].datatype = 9
    elif change == "past_point_step":
        msg.fields[4].offset = msg.point_step - 2
    elif change == "count_x":
        msg.fields[0].count = 3
    elif change == "count_time":
        msg.fields[3].count = 2
    elif change == "truncated":
        msg.data = msg.data[:-1]
    elif change == "unit_s_for_ns":
        options = TimeOptions(unit="s")
    elif change == "nan_time":
        options = TimeOptions(field="time")
    elif change == "missing_named_time":
        options = TimeOptions(field="stamp")
    with pytest.raises(CloudError) as new:
        decode(msg, "/lidar msg 3", options)
    with pytest.raises(CloudError) as old:
        reference_decode(msg, "/lidar msg 3", options)
    assert str(new.value) == str(old.value)
    assert str(new.value).startswith("/lidar msg 3: ")
