"""`farlio.simulation.rotation_from_origin_deg`: the rotation error of a trajectory relative to its
first pose. A trajectory rotated as a whole (a map frame levelled with a small error) has none; a
constant rotation of every body after the first, or a heading error growing by a known rate, gives
the angle's RMS computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")

from farlio.simulation import rotation_from_origin_deg  # noqa: E402


def _rz(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rx(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _pose(rotation: np.ndarray, translation) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = translation
    return m


def _truth(n: int) -> list:
    """A drive along x turning at 0.05 rad a pose."""
    return [(1000 + k, core.SE3.from_matrix(_pose(_rz(0.05 * k), [2.0 * k, 0.1 * k * k, 0.0]))) for k in range(n)]


def _estimate(poses: list[np.ndarray], first_stamp: int = 1000) -> object:
    t = core.Trajectory()
    for k, m in enumerate(poses):
        t.push_back(first_stamp + k, core.SE3.from_matrix(m))
    return t


def test_a_trajectory_rotated_as_a_whole_has_no_error():
    truth = _truth(20)
    tilt = _rx(math.radians(0.5))  # a map frame levelled 0.5 deg off
    estimate = [_pose(tilt @ p.matrix()[:3, :3], tilt @ p.matrix()[:3, 3]) for _, p in truth]
    assert rotation_from_origin_deg(_estimate(estimate), truth) == pytest.approx(0.0, abs=1e-6)


def test_a_heading_error_growing_at_a_known_rate_gives_its_rms():
    truth = _truth(21)
    rate_deg = 0.01  # each pose 0.01 deg more in heading than the truth
    estimate = [
        _pose(p.matrix()[:3, :3] @ _rz(math.radians(rate_deg * k)), p.matrix()[:3, 3]) for k, (_, p) in enumerate(truth)
    ]
    expected = math.sqrt(sum((rate_deg * k) ** 2 for k in range(21)) / 21)
    assert rotation_from_origin_deg(_estimate(estimate), truth) == pytest.approx(expected, rel=1e-6)


def test_every_pose_after_the_first_turned_by_the_same_roll():
    truth = _truth(10)
    roll = _rx(math.radians(0.2))
    estimate = [
        p.matrix() if k == 0 else _pose(p.matrix()[:3, :3] @ roll, p.matrix()[:3, 3]) for k, (_, p) in enumerate(truth)
    ]
    expected = math.sqrt(9 * 0.2**2 / 10)
    assert rotation_from_origin_deg(_estimate(estimate), truth) == pytest.approx(expected, rel=1e-6)


def test_a_stamp_without_truth_gives_nan():
    truth = _truth(5)
    estimate = _estimate([p.matrix() for _, p in truth], first_stamp=5000)
    assert math.isnan(rotation_from_origin_deg(estimate, truth))
