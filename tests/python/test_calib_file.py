"""`--calib` files and extrinsic matrices go through the C++ reader and its rigidity check."""
from __future__ import annotations

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")

from farlio.datasets.calib import CalibFile, se3_from_matrix  # noqa: E402, F401


def test_a_matrix_with_nan_is_not_rigid():
    m = np.eye(4)
    m[1, 3] = float("nan")
    with pytest.raises(ValueError, match="calib_imu_to_velo.txt"):
        se3_from_matrix(m, "calib_imu_to_velo.txt")
