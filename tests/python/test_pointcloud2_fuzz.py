"""Randomised mutation of PointCloud2-like messages: the PointCloud2 decoder is Python
and numpy, so instead of a libFuzzer target it gets this property test. Valid messages of the
drivers' layouts (pointcloud2_encode) are mutated at random: width, height, point_step, row_step,
field offsets, datatypes, counts and names, endianness, stamps, and the data cut, extended or
overwritten. Every decode must either return a consistent Cloud or raise CloudError (a
ValueError naming the message); any other exception (IndexError, TypeError, a numpy error,
MemoryError) fails the test with the mutation that caused it."""

from __future__ import annotations

import copy
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("farlio._core")

from farlio.datasets.pointcloud2 import POINTFIELD_TYPES, CloudError, TimeOptions, decode  # noqa: E402
from farlio.datasets.pointcloud2_encode import CONVENTIONS, encode  # noqa: E402

SEED = 13
MUTATIONS = 3000
POINTS = 16
START_NS = 1_700_000_000_000_000_000
END_NS = START_NS + 100_000_000
#: values a mutated size field takes: edge cases and random ones
EDGE_SIZES = (0, 1, 2, 3, 4, 7, 8, 255, 2**16, 2**31 - 1, 2**32 - 1, 2**62)
MAX_RANDOM_SIZE = 2**40


def valid_message(rng: np.random.Generator, driver: str) -> SimpleNamespace:
    pts = rng.uniform(-50.0, 50.0, (POINTS, 3)).astype(np.float32)
    times = np.sort(rng.uniform(0.0, 0.1, POINTS)).astype(np.float32)
    enc = encode(pts, times, rng.uniform(0, 255, POINTS).astype(np.float32), START_NS, END_NS, driver)
    fields = [SimpleNamespace(name=n, offset=o, datatype=d, count=1) for n, o, d in enc.fields]
    stamp = SimpleNamespace(sec=enc.header_ns // 10**9, nanosec=enc.header_ns % 10**9)
    return SimpleNamespace(
        header=SimpleNamespace(stamp=stamp, frame_id="lidar"),
        height=1,
        width=enc.width,
        fields=fields,
        is_bigendian=False,
        point_step=enc.point_step,
        row_step=enc.point_step * enc.width,
        data=enc.data.tobytes(),
        is_dense=True,
    )


def size_value(rng: np.random.Generator, current: int) -> int:
    choice = rng.integers(4)
    if choice == 0:
        return int(rng.choice(EDGE_SIZES))
    if choice == 1:
        return max(current + int(rng.integers(-8, 9)), 0)
    return int(rng.integers(0, min(4 * max(current, 1), MAX_RANDOM_SIZE) + 1))


def mutate(rng: np.random.Generator, msg: SimpleNamespace) -> str:
    """Applies one random mutation in place; returns what it did (for the failure message)."""
    kind = int(rng.integers(9))
    if kind == 0:
        attr = str(rng.choice(["width", "height", "point_step", "row_step"]))
        setattr(msg, attr, size_value(rng, getattr(msg, attr)))
        return f"{attr}={getattr(msg, attr)}"
    if kind in (1, 2, 3) and msg.fields:
        f = msg.fields[int(rng.integers(len(msg.fields)))]
        if kind == 1:
            f.offset = size_value(rng, f.offset)
            return f"field {f.name} offset={f.offset}"
        if kind == 2:
            f.datatype = int(rng.integers(0, 10))
            return f"field {f.name} datatype={f.datatype}"
        f.count = int(rng.choice([0, 1, 2, 3, 2**20, 2**31]))
        return f"field {f.name} count={f.count}"
    if kind == 4 and msg.fields:
        k = int(rng.integers(len(msg.fields)))
        other = str(rng.choice(["x", "y", "z", "t", "time", "timestamp", "intensity", "?", ""]))
        if rng.integers(2):
            msg.fields[k].name = other
        else:
            del msg.fields[k]
        return f"field {k} renamed/removed ({other})"
    if kind == 5:
        data = bytearray(msg.data)
        cut = int(rng.integers(0, len(data) + 1))
        msg.data = bytes(data[:cut]) if rng.integers(2) else bytes(data) + bytes(rng.integers(0, 256, cut, np.uint8))
        return f"data length {len(msg.data)}"
    if kind == 6 and msg.data:
        data = np.frombuffer(msg.data, np.uint8).copy()
        idx = rng.integers(0, len(data), int(rng.integers(1, 16)))
        data[idx] = rng.integers(0, 256, len(idx), np.uint8)
        msg.data = data.tobytes()
        return f"{len(idx)} data bytes overwritten"
    if kind == 7:
        msg.is_bigendian = not msg.is_bigendian
        return f"is_bigendian={msg.is_bigendian}"
    msg.header.stamp.sec = int(rng.choice([0, 1, 2**31 - 1, 2**32 - 1]))
    return f"stamp sec={msg.header.stamp.sec}"


def check_cloud(cloud, where: str) -> None:
    n = len(cloud.points)
    assert cloud.points.shape == (n, 3), where
    if cloud.intensity is not None:
        assert cloud.intensity.shape == (n,), where
    if cloud.offset_s is not None:
        assert cloud.offset_s.shape == (n,), where


@pytest.mark.parametrize("driver", sorted(CONVENTIONS))
def test_mutated_pointcloud2_decodes_or_raises_cloud_error(driver: str) -> None:
    rng = np.random.default_rng([SEED, sorted(CONVENTIONS).index(driver)])
    base = valid_message(rng, driver)
    check_cloud(decode(base, "valid"), "valid")
    options = [TimeOptions(), TimeOptions(unit="ns"), TimeOptions(header_stamp="end"), TimeOptions(field="none")]
    outcomes = {"decoded": 0, "CloudError": 0}
    for i in range(MUTATIONS):
        msg = copy.deepcopy(base)
        done = [mutate(rng, msg) for _ in range(int(rng.integers(1, 4)))]
        where = f"mutation {i}: {'; '.join(done)}"
        try:
            check_cloud(decode(msg, where, options[i % len(options)]), where)
            outcomes["decoded"] += 1
        except CloudError as e:
            assert where in str(e), f"the error does not name the message: {e}"
            outcomes["CloudError"] += 1
        except Exception as e:  # noqa: BLE001 - anything else is the finding
            pytest.fail(f"{where}: {type(e).__name__}: {e}")
    # The mutations reach both outcomes (a mutator that only ever breaks the message tests little).
    assert outcomes["decoded"] > MUTATIONS // 20 and outcomes["CloudError"] > MUTATIONS // 20, outcomes
    assert set(POINTFIELD_TYPES) <= set(range(1, 9))


def test_row_step_shorter_than_a_row_is_an_error() -> None:
    """Rows that would overlap (row_step < width * point_step) gave duplicated points."""
    msg = valid_message(np.random.default_rng(SEED), "ouster")
    msg.height, msg.width = 2, msg.width // 2
    msg.row_step = msg.width * msg.point_step - 1
    with pytest.raises(CloudError, match="row_step .* is shorter than a row"):
        decode(msg, "overlapping rows")
