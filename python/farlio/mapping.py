"""Maps of a run: the whole map written with --save-map (map.pcd, map.ply, map.png), and
localization in a prior map with --prior-map (the map's frame is the world frame of the run).

The whole map is accumulated as the run goes (_core.MapExport: every scan whose pose was used,
undistorted, at its registered pose, one centroid per cell of the export resolution); only the
tiles (map.export_tile_m) the sensor can reach stay in memory, the others wait in the output
folder's .map_tiles/ until the end of the run, when the map is streamed into map.pcd and map.ply
tile by tile."""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import farlio
from farlio import _core

MAP_PLY, MAP_PCD = "map.ply", "map.pcd"
MAP_GLOBAL_PLY, MAP_GLOBAL_PCD, MAP_GLOBAL_PNG = "map_global.ply", "map_global.pcd", "map_global.png"
#: where the whole map's tiles the sensor has left wait during a run (removed at its end)
SPILL_DIR = ".map_tiles"
MS_PER_S = 1e3
#: --initial-pose: X Y Z in metres, ROLL PITCH YAW in degrees
INITIAL_POSE_VALUES = 6


@dataclass
class MapOptions:
    """What a run does with maps: save (--save-map) at resolution_m (None: the config's
    map.export_resolution_m, whose 0 means the map's point spacing); localize in prior_map
    (--prior-map) starting from initial_pose (X Y Z m, ROLL PITCH YAW deg; None: the origin); close
    loops (--loop-closure)."""

    save: bool = False
    resolution_m: float | None = None
    prior_map: Path | None = None
    initial_pose: Sequence[float] | None = None
    loop_closure: bool = False  # --loop-closure: the global trajectory (loop_closure.py)


def pose_from_xyz_rpy_deg(values: Sequence[float]) -> Any:
    """The SE3 of X Y Z (m) and ROLL PITCH YAW (deg), R = Rz(yaw) Ry(pitch) Rx(roll)."""
    if len(values) != INITIAL_POSE_VALUES or not all(math.isfinite(v) for v in values):
        raise ValueError(f"an initial pose is X Y Z ROLL PITCH YAW (6 finite numbers), got {list(values)}")
    m = np.eye(4)
    m[:3, :3] = _core.rotation_from_euler(np.radians(np.asarray(values[3:], dtype=np.float64)))
    m[:3, 3] = values[:3]
    return _core.SE3.from_matrix(m)


def load_prior_map(odo: Any, options: MapOptions) -> int:
    """Hands the prior map and the initial pose to the odometry before its first scan; returns the
    map's point count. ValueError naming the file when it cannot be read or holds no point."""
    if options.initial_pose is not None:
        odo.set_initial_pose(pose_from_xyz_rpy_deg(options.initial_pose))
    if options.prior_map is None:
        return 0
    cloud = _core.io.read_point_cloud(Path(options.prior_map))
    cloud.remove_non_finite()
    if len(cloud) == 0:
        raise ValueError(f"{options.prior_map}: the prior map holds no point")
    odo.set_prior_map(cloud)
    return len(cloud)


class WholeMap:
    """The whole map of a run under construction (--save-map) and its files."""

    def __init__(self, resolution_m: float | None, out_dir: Path):
        self.requested_resolution_m = resolution_m
        self.spill_dir = Path(out_dir) / SPILL_DIR
        self.export: Any = None
        self.add_ms: list[float] = []
        self.most_cells_in_memory = 0

    def add(self, odo: Any, scan: Any, frame: Any) -> None:
        """A processed scan whose pose was used (not a failure, not lost in a prior map)."""
        r = frame.scan
        if not frame.processed or r.failure:
            return
        if self.export is None:  # the export resolution may follow the voxel size fixed at the first scan
            config = odo.effective_config
            if self.requested_resolution_m is not None:
                config.set("map.export_resolution_m", self.requested_resolution_m)
            self.export = _core.MapExport(_core.export_resolution_m(config), config, str(self.spill_dir))
        start = time.perf_counter()
        self.export.add(scan, r)
        self.add_ms.append((time.perf_counter() - start) * MS_PER_S)
        self.most_cells_in_memory = max(self.most_cells_in_memory, self.export.cells_in_memory)

    def write(self, out_dir: Path, trajectory: Path, plot: bool) -> dict[str, Any]:
        """map.pcd and map.ply (x y z intensity, world frame), streamed tile by tile, and map.png;
        returns the summary's "map" entry (cells, resolution, memory, time per scan)."""
        e = self.export
        if e is not None:
            e.write([out_dir / MAP_PCD, out_dir / MAP_PLY])
        else:  # no scan was used: empty files
            empty = farlio.Scan(np.zeros((0, 3), np.float32))
            _core.io.write_pcd(out_dir / MAP_PCD, empty)
            _core.io.write_ply(out_dir / MAP_PLY, empty)
        if plot:
            from .plots import MAP_PNG, plot_map

            plot_map(np.asarray(_core.io.read_point_cloud(out_dir / MAP_PCD).points), trajectory, out_dir / MAP_PNG)
        summary = {
            "points": e.cells if e else 0,
            "resolution_m": e.resolution_m if e else None,
            "points_added": e.points_added if e else 0,
            "most_cells_in_memory": self.most_cells_in_memory,
            "memory_bytes": e.memory_bytes if e else 0,
            "add_ms_median": float(np.median(self.add_ms)) if self.add_ms else None,
            "add_ms_p99": float(np.percentile(self.add_ms, 99)) if self.add_ms else None,
        }
        self.export = None  # removes the tiles' files and the folder
        return summary


def downsample(points: np.ndarray, resolution_m: float) -> np.ndarray:
    """One centroid per cell of resolution_m."""
    if len(points) == 0:
        return points
    keys = np.floor(points / resolution_m).astype(np.int64)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, inverse.ravel(), points)
    return (sums / counts[:, None]).astype(np.float32)


def write_global_map(loops: Any, resolution_m: float, out_dir: Path, trajectory: Path, plot: bool) -> dict[str, Any]:
    """map_global.pcd, map_global.ply (and map_global.png, with the accepted loops): every
    keyframe's segment at its optimised pose, one centroid per cell; returns the summary's entry."""
    points = downsample(loops.global_points(), resolution_m)
    cloud = farlio.Scan(points)
    _core.io.write_pcd(out_dir / MAP_GLOBAL_PCD, cloud)
    _core.io.write_ply(out_dir / MAP_GLOBAL_PLY, cloud)
    if plot:
        from .plots import plot_map

        plot_map(points, trajectory, out_dir / MAP_GLOBAL_PNG, loops.accepted_loop_ends())
    return {"points": len(points), "resolution_m": resolution_m}
