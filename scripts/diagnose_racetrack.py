#!/usr/bin/env python3
"""The racetrack failure (docs/odometry.md): registers each scan of a generated racetrack
sequence starting from its TRUE pose (the scan pipeline's map built from the previous true
poses too) and prints how far the registration moves it. Usage:
  farlio simulate racetrack --duration 6 --out rt && python scripts/diagnose_racetrack.py rt [name=value ...]
"""
from __future__ import annotations

import sys

import numpy as np

import farlio
from farlio import _core


def main() -> None:
    reader = _core.io.SequenceReader(sys.argv[1])
    T = reader.calibration().T_imu_lidar
    G = reader.groundtruth_scans().matrices()
    cfg = _core.Config()
    for item in sys.argv[2:]:
        cfg.set(*item.split("=", 1))
    pipe = _core.ScanPipeline(cfg, farlio.SE3.from_matrix(G[0]) * T)
    for i in range(min(len(G), reader.num_scans())):
        truth = farlio.SE3.from_matrix(G[i]) * T
        r = pipe.process(reader.read_scan(i), truth)
        e = truth.inverse() * r.pose
        if i % 10 == 0:
            print(f"scan {i:4d}: moved {np.linalg.norm(e.translation):.3f} m / {np.degrees(e.angle_rad()):.3f} deg "
                  f"from the true pose ({r.iterations} iterations)")


if __name__ == "__main__":
    main()
