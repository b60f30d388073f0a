#!/usr/bin/env python3
"""The racetrack launch (docs/odometry.md, "Measured figures"): every 5th scan of a generated
racetrack sequence, undistorted with the TRUE motion, is registered against the first (standstill) scan starting from
its TRUE pose; prints how far the registration moves it. A false minimum at "no motion" shows as
a move of minus the distance travelled. Usage:
  farlio simulate racetrack --duration 6 --out rt && python figures/odometry_racetrack_launch.py rt [name=value ...]
e.g. registration.point_to_point_sigma_m=0.0316 registration.skip_line_pairs=false (the paper's weighting).
"""

from __future__ import annotations

import argparse

import farlio
import numpy as np
from farlio import _core
from farlio._core import NS_PER_S

FIRST_MOVING_SCAN = 40  # the profile stands still for 2 s (40 scans at 20 Hz)
EVERY = 5


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("sequence", help="a generated racetrack sequence folder (farlio simulate racetrack)")
    p.add_argument("overrides", nargs="*", metavar="NAME=VALUE", help="config fields of the registration")
    args = p.parse_args()
    seq = args.sequence
    reader = _core.io.SequenceReader(seq)
    T = reader.calibration().T_imu_lidar.matrix()
    G = reader.groundtruth_scans().matrices()
    gt = np.loadtxt(f"{seq}/groundtruth.tum")  # dense body poses; the launch is straight: no rotation
    cfg = _core.Config()
    for item in args.overrides:
        cfg.set(*item.split("=", 1))

    def position_at(t: np.ndarray) -> np.ndarray:
        i = np.clip(np.searchsorted(gt[:, 0], t), 1, len(gt) - 1)
        a = ((t - gt[i - 1, 0]) / (gt[i, 0] - gt[i - 1, 0]))[:, None]
        return gt[i - 1, 1:4] * (1 - a) + gt[i, 1:4] * a

    def undistorted(i: int) -> farlio.Scan:
        s = reader.read_scan(i)
        pts = np.asarray(s.points, dtype=np.float64)
        t = s.start_stamp_ns / NS_PER_S + np.asarray(s.time_s, dtype=np.float64)  # float64: stamps ~1.7e9 s
        shift_world = position_at(t) - position_at(np.array([s.end_stamp_ns / NS_PER_S]))
        body = pts @ T[:3, :3].T + T[:3, 3] + shift_world @ G[i][:3, :3]
        return farlio.Scan(((body - T[:3, 3]) @ T[:3, :3]).astype(np.float32))

    target = reader.read_scan(0)
    P0 = farlio.SE3.from_matrix(G[0] @ T)
    worst = 0.0
    for i in range(FIRST_MOVING_SCAN, reader.num_scans(), EVERY):
        truth = P0.inverse() * farlio.SE3.from_matrix(G[i] @ T)
        r = _core.register_pair(undistorted(i), target, truth, cfg)
        moved = (truth.inverse() * r.pose).translation
        worst = max(worst, float(np.linalg.norm(moved)))
        print(
            f"scan {i:4d}: travelled {np.linalg.norm(truth.translation):6.2f} m, registration moved "
            f"{np.linalg.norm(moved):.3f} m (along x {moved[0]:+.3f} m) from the true pose"
        )
    print(f"largest move: {worst:.3f} m")


if __name__ == "__main__":
    main()
