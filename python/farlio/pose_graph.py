"""The pose graph of loop closure: one node per keyframe (its LiDAR pose in the global frame),
odometry edges between consecutive keyframes and loop edges between a keyframe and the place it
revisits, optimised incrementally with gtsam's iSAM2 (the extra `pip install 'farlio[mapping]'`).

Odometry edges carry a drift model: the odometry's relative pose over d metres is trusted to
ODOMETRY_TRANSLATION_DRIFT * d (m) and ODOMETRY_ROTATION_DRIFT_RAD_PER_M * d (rad), about the
RPE the odometry reaches on the project's sequences (0.2-0.7 %, docs/odometry.md) with margin. Loop
edges carry the covariance of their verifying registration and a Cauchy kernel, so that a loop the
verification let through wrongly pulls the graph far less than its square error would."""

from __future__ import annotations

from typing import Any

import numpy as np

MAPPING_EXTRA = "pip install 'farlio[mapping]'"
#: odometry edges: standard deviation per metre travelled (translation, as a fraction)
ODOMETRY_TRANSLATION_DRIFT = 0.01
#: odometry edges: rotation standard deviation per metre travelled (rad/m; 0.03 deg/m)
ODOMETRY_ROTATION_DRIFT_RAD_PER_M = 5e-4
#: floor of the odometry edges' standard deviations (m, rad): keyframes closer than a metre
ODOMETRY_MIN_SIGMA = (0.01, 1e-3)
#: the first keyframe is held where the odometry put it (m, rad)
ANCHOR_SIGMA = 1e-6
#: Cauchy kernel of the loop edges, in standard deviations of their registration
LOOP_KERNEL_SCALE = 1.0


def import_gtsam() -> Any:
    """gtsam, or ImportError naming the extra that installs it."""
    try:
        import gtsam
    except ImportError as e:
        raise ImportError(f"loop closure needs gtsam: {MAPPING_EXTRA}") from e
    return gtsam


def _sigmas(rotation_rad: float, translation_m: float) -> np.ndarray:
    """gtsam's Pose3 tangent order: rotation first, then translation."""
    return np.array([rotation_rad] * 3 + [translation_m] * 3)


class PoseGraph:
    """Keyframe poses (4x4 LiDAR poses) optimised with iSAM2 as keyframes and loops arrive."""

    def __init__(self) -> None:
        self.gtsam = import_gtsam()
        self.isam = self.gtsam.ISAM2()
        self.odometry: list[np.ndarray] = []  # the odometry's pose of every keyframe
        self.estimate: Any = None
        self.loops = 0

    def __len__(self) -> int:
        return len(self.odometry)

    def add_keyframe(self, T_odom: np.ndarray, travelled_m: float) -> int:
        """A keyframe at the odometry's pose T_odom, travelled_m after the previous one; returns its
        index. Its global pose starts as the previous global pose moved by the odometry's step."""
        g = self.gtsam
        k = len(self.odometry)
        graph, values = g.NonlinearFactorGraph(), g.Values()
        if k == 0:
            anchor = g.noiseModel.Isotropic.Sigma(6, ANCHOR_SIGMA)
            graph.add(g.PriorFactorPose3(k, g.Pose3(T_odom), anchor))
            values.insert(k, g.Pose3(T_odom))
        else:
            step = np.linalg.inv(self.odometry[-1]) @ T_odom
            sigma = _sigmas(
                max(ODOMETRY_MIN_SIGMA[1], ODOMETRY_ROTATION_DRIFT_RAD_PER_M * travelled_m),
                max(ODOMETRY_MIN_SIGMA[0], ODOMETRY_TRANSLATION_DRIFT * travelled_m),
            )
            graph.add(g.BetweenFactorPose3(k - 1, k, g.Pose3(step), g.noiseModel.Diagonal.Sigmas(sigma)))
            values.insert(k, g.Pose3(self.pose(k - 1) @ step))
        self.odometry.append(np.asarray(T_odom, dtype=np.float64))
        self.isam.update(graph, values)
        self.estimate = self.isam.calculateEstimate()
        return k

    def add_loop(self, i: int, j: int, T_i_j: np.ndarray, covariance: np.ndarray) -> None:
        """A loop edge: keyframe j seen from keyframe i at T_i_j, with its 6x6 covariance in gtsam's
        tangent order (rotation, translation)."""
        g = self.gtsam
        base = g.noiseModel.Gaussian.Covariance(np.asarray(covariance, dtype=np.float64))
        robust = g.noiseModel.Robust.Create(g.noiseModel.mEstimator.Cauchy.Create(LOOP_KERNEL_SCALE), base)
        graph = g.NonlinearFactorGraph()
        graph.add(g.BetweenFactorPose3(i, j, g.Pose3(T_i_j), robust))
        self.isam.update(graph, g.Values())
        self.isam.update()  # a loop moves many keyframes: one more relinearisation step
        self.estimate = self.isam.calculateEstimate()
        self.loops += 1

    def pose(self, k: int) -> np.ndarray:
        """The global pose of keyframe k (4x4)."""
        return self.estimate.atPose3(k).matrix()

    def poses(self) -> list[np.ndarray]:
        """Every keyframe's global pose (4x4), in keyframe order, read from the estimate at once."""
        rows = self.gtsam.utilities.extractPose3(self.estimate)  # (K, 12): R row by row, then t
        out = []
        for r in rows:
            m = np.eye(4)
            m[:3, :3] = r[:9].reshape(3, 3)
            m[:3, 3] = r[9:]
            out.append(m)
        return out
