#!/usr/bin/env python3
"""How well-determined is ../shared/data/real/scan_pair? (docs/odometry.md, "Measured figures": the
real scan pair.) Registers it with farlio (the automatic voxel, 4, 2 and 1 m) and, if the `small_gicp` package is
installed (pip install small_gicp), with small_gicp's factors at several downsampling resolutions,
printing each result's distance to T_target_source.txt. Used to set the bounds of
tests/cpp/test_scan_pair.cpp.

    python figures/odometry_scan_pair.py [DIR]   (DIR: the pair's folder, default ../shared/data/real/scan_pair)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import farlio
import numpy as np
from farlio import _core

#: ../shared/data/real/scan_pair next to the repository
DEFAULT_DATA = Path(__file__).resolve().parents[2] / "shared/data/real/scan_pair"


def error(gt: np.ndarray, T: np.ndarray) -> tuple[float, float]:
    e = np.linalg.inv(gt) @ T
    return float(np.linalg.norm(e[:3, 3])), float(np.degrees(np.arccos(np.clip((np.trace(e[:3, :3]) - 1) / 2, -1, 1))))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", nargs="?", type=Path, default=DEFAULT_DATA, help="the scan pair's folder")
    data = p.parse_args().data
    gt = np.loadtxt(data / "T_target_source.txt")
    src = _core.io.read_point_cloud(data / "source.ply")
    tgt = _core.io.read_point_cloud(data / "target.ply")
    for voxel in ("auto", 4.0, 2.0, 1.0):
        cfg = _core.Config()
        if voxel != "auto":  # a fixed size (auto picks one no larger than map.voxel_size_m)
            cfg.set("map.auto_voxel_size", "false")
            cfg.set("map.voxel_size_m", str(voxel))
        r = _core.register_pair(src, tgt, farlio.SE3(), cfg)
        print(
            f"farlio voxel {voxel} m: translation {error(gt, r.pose.matrix())[0]:.4f} m, "
            f"rotation {error(gt, r.pose.matrix())[1]:.4f} deg"
        )
    try:
        import small_gicp
    except ImportError:
        print("small_gicp not installed: skipping its rows")
        return
    T = small_gicp.read_ply(str(data / "target.ply"))
    S = small_gicp.read_ply(str(data / "source.ply"))
    for res in (0.1, 0.25, 0.5, 1.0):
        for reg in ("GICP", "VGICP", "PLANE_ICP", "ICP"):
            r = small_gicp.align(
                T.points(),
                S.points(),
                registration_type=reg,
                downsampling_resolution=res,
                voxel_resolution=max(4 * res, 1.0),
                num_threads=2,
            )
            t, a = error(gt, r.T_target_source)
            print(f"small_gicp {reg:9s} downsampling {res:4.2f} m: translation {t:.4f} m, rotation {a:.4f} deg")


if __name__ == "__main__":
    main()
