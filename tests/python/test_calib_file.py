"""`--calib` files and extrinsic matrices go through the C++ reader and its rigidity check."""

from __future__ import annotations

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")

from farlio.datasets.calib import CalibFile, se3_from_matrix  # noqa: E402

IDENTITY_ROWS = "[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]"
SHIFTED_ROWS = "[[1, 0, 0, 1.5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]"


def test_single_matrix_serves_every_lidar_and_gravity_is_optional(tmp_path):
    path = tmp_path / "calib.yaml"
    path.write_text(f"T_imu_lidar: {SHIFTED_ROWS}\n")
    calib = CalibFile(path)
    assert calib.gravity_m_s2 is None
    assert calib.T_imu_lidar("/any", "frame").translation[0] == 1.5
    path.write_text(f"T_imu_lidar: {SHIFTED_ROWS}\ngravity: 9.79\n")
    assert CalibFile(path).gravity_m_s2 == 9.79


def test_mapping_by_topic_or_frame(tmp_path):
    path = tmp_path / "calib.yaml"
    path.write_text(f"T_imu_lidar:\n  /front: {IDENTITY_ROWS}\n  rear: {SHIFTED_ROWS}\n")
    calib = CalibFile(path)
    assert calib.T_imu_lidar("/rear", "rear").translation[0] == 1.5
    assert calib.T_imu_lidar("/front").translation[0] == 0.0
    with pytest.raises(ValueError, match=r"calib.yaml: T_imu_lidar has no entry for '/top' \(entries: /front, rear\)"):
        calib.T_imu_lidar("/top")


def test_bad_files_name_the_file_and_the_key(tmp_path):
    path = tmp_path / "calib.yaml"
    path.write_text("T_imu_lidar:\n  /front: [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n")
    with pytest.raises(core.InputError, match=r"calib.yaml: key 'T_imu_lidar\[/front\]': not a rigid transform"):
        CalibFile(path)
    path.write_text("gravity: 9.81\n")
    with pytest.raises(ValueError, match="calib.yaml: missing key 'T_imu_lidar'"):
        CalibFile(path)


def test_matrices_use_the_same_rigidity_check(tmp_path):
    m = np.eye(4)
    m[:3, 3] = [1.0, 2.0, 3.0]
    np.testing.assert_allclose(se3_from_matrix(m, "x").matrix(), m, atol=1e-15)
    m[0, 1] = 1e-3  # far from orthonormal
    with pytest.raises(ValueError, match="calib_imu_to_velo.txt: not a rigid transform: the rotation block"):
        se3_from_matrix(m, "calib_imu_to_velo.txt")
    with pytest.raises(ValueError, match="expected a 4x4 matrix"):
        se3_from_matrix(np.eye(3), "x")


def test_a_matrix_with_nan_is_not_rigid():
    m = np.eye(4)
    m[1, 3] = float("nan")
    with pytest.raises(ValueError, match="calib_imu_to_velo.txt"):
        se3_from_matrix(m, "calib_imu_to_velo.txt")
