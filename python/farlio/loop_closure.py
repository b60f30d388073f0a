"""Loop closure: a globally consistent trajectory from the odometry's scans (farlio run
--loop-closure).

Along the odometry, a keyframe starts every loop.keyframe_distance_m of travel; the scans until
the next one (undistorted with the motion the odometry used, at the export resolution) form its
segment, in the keyframe's frame. A keyframe's submap is its segment with those of the
loop.submap_length_m of path before it. When a keyframe's segment is complete:

1. candidates: earlier keyframes at least MIN_LOOP_TRAVEL_FACTOR submap lengths back along the
   path whose global position (the pose graph's current estimate) lies within loop.search_radius_m
   plus SEARCH_DRIFT of the path between them, and within the height the odometry can drift over
   that path (vertical_drift_m); the nearest is verified;
2. verification by farlio's own GICP (register_pair), coarse to fine from the graph's guess: the
   query's submap against the candidate's (and its neighbours'), accepted only when
   - at least loop.min_overlap of the query's cells land on the candidate's map, and
   - the same registration started AMBIGUITY_OFFSET_M away along each horizontal axis (and
     AMBIGUITY_YAW_RAD turned) comes back within loop.max_ambiguity_m of the same pose, or ends
     at a clearly worse fit: a straight with evenly spaced posts or two identical corridors let
     a registration lock onto the wrong copy, which fits as well, and then the starts disagree.
     A start that stalls in a local minimum (still turned, and a clearly worse fit) is no rival;
   - the height it corrects is within what the odometry can drift over the path between the two
     (vertical_drift_m). A parking garage's levels look alike from inside, and a query's submap
     slides onto the level below as readily as the starts above slide along a straight; but the
     level below is a level height away, which the odometry does not drift by over a few
     hundred metres. The ambiguity test cannot see it: the candidate's submap holds its own
     level only;
3. the pose graph (pose_graph.py) gets the loop edge and is optimised (iSAM2), unless the graph
   already agrees with the loop within the loop edge's standard deviations (LOOP_SIGMA).

After a loop is accepted the next loop.submap_length_m of travel is not searched (one loop per
submap is enough to hold the graph, and verification is the expensive step), after a candidate
refused as ambiguous the next half submap length.

Outputs (write): scans_lidar_global.tum and scans_body_global.tum, every scan's pose corrected
through its keyframe, and loops.csv, every verified candidate with its figures, the reason it was
refused, and the registration's pose of the query keyframe in the match's frame (tx ty tz qx qy qz
qw). The odometry's own outputs are unchanged."""

from __future__ import annotations

import csv
import math
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import farlio
from farlio import _core

from .pose_graph import PoseGraph

SCANS_LIDAR_GLOBAL_TUM, SCANS_BODY_GLOBAL_TUM, LOOPS_CSV = (
    "scans_lidar_global.tum",
    "scans_body_global.tum",
    "loops.csv",
)
#: a candidate is at least this many submap lengths back along the path (its submap shares no scan)
MIN_LOOP_TRAVEL_FACTOR = 2.0
#: the search radius grows by this fraction of the path between query and candidate (odometry drift)
SEARCH_DRIFT = 0.005
#: the height a loop may correct, and a candidate's estimate differ by: VERTICAL_DRIFT_M plus
#: VERTICAL_DRIFT of the path between query and candidate. The odometry's own height error is
#: 0.5-4 m RMS over the racetrack's two laps (8.3 km; 20 m allowed per 4 km lap) and 0.2 m RMS in
#: the simulator's parking garage (docs/maps.md), whose next level is 3.2 m away over 160 m of path
#: (a ramp lap): three times the 1.1 m this allows there.
VERTICAL_DRIFT_M, VERTICAL_DRIFT = 0.3, 0.005
#: after a candidate refused as ambiguous, the search waits this fraction of a submap length: the
#: next keyframes' submaps share most of its scans (a straight stays ambiguous for its length)
RETRY_AFTER_AMBIGUOUS = 0.5
#: coarse to fine: the registration's sigma (correspondences within 3 sigma) at each stage, m
STAGE_SIGMAS_M = (3.0, 1.0, 0.3)
#: the ambiguity check's starts: this far along each horizontal axis of the found pose, m
AMBIGUITY_OFFSET_M = 4.0
#: and turned by this much about the vertical, rad (10 deg)
AMBIGUITY_YAW_RAD = math.radians(10.0)
#: a start stalled in a local minimum (a 10 deg turn is 7 m at the far end of a 40 m submap) is no
#: rival of the found pose: it kept more than this fraction of its start's turn, and fits clearly
#: worse, with less than AMBIGUITY_MIN_FIT of the found pose's inliers (15-30 % on the racetrack).
#: Along a featureless straight a start shifted along it keeps its shift but turns back: a rival.
AMBIGUITY_STALLED_TURN = 0.5
AMBIGUITY_MIN_FIT = 0.8
#: overlap: cells of this many export resolutions
OVERLAP_CELL_FACTOR = 2.0
#: standard deviations of an accepted loop edge (translation m, rotation rad); a loop whose pose is
#: within both of the graph's estimate is accepted but not added (it would only add its error)
LOOP_SIGMA = (0.05, math.radians(0.2))
AMBIGUOUS = "ambiguous"


@dataclass
class Keyframe:
    """A pose-graph node: the odometry's LiDAR pose at its first scan, where it lies along the
    path, its segment's points (its frame) and its scans' poses relative to it."""

    T_odom: np.ndarray
    path_m: float
    stamp_ns: int
    scans: list[tuple[int, np.ndarray]] = field(default_factory=list)
    points: np.ndarray | None = None  # (N, 3) float32 once the segment is complete
    export: Any = None  # the segment under construction from raw scans (_core.MapExport)
    chunks: list[np.ndarray] = field(default_factory=list)  # or from registered points (its frame)


@dataclass
class LoopRecord:
    """One verified candidate (a row of loops.csv)."""

    query: int
    match: int
    query_stamp_ns: int
    match_stamp_ns: int
    distance_m: float  # between their global positions before the loop
    overlap: float
    correction_m: float  # the verified pose against the graph's guess
    correction_deg: float
    ambiguity_m: float  # largest disagreement of the ambiguity check's rival ends
    stalled_starts: int  # the ambiguity check's starts that ended at a clearly worse fit
    accepted: bool
    in_graph: bool  # accepted and a pose-graph edge (not when the graph already agreed within LOOP_SIGMA)
    reason: str  # why it was refused ('' when accepted)
    time_s: float
    T_match_query: np.ndarray = field(default=None, repr=False)  # the registration's result

    def row(self) -> list[Any]:
        """The loops.csv row: the fields, then T_match_query as tx ty tz qx qy qz qw."""
        T = self.T_match_query
        pose = [math.nan] * 7
        if T is not None and np.all(np.isfinite(T)):
            pose = [*T[:3, 3], *_core.SE3.from_matrix(T).quaternion_xyzw]
        return [getattr(self, name) for name in LOOPS_CSV_FIELDS] + pose


#: the columns of loops.csv
LOOPS_CSV_FIELDS = [name for name in LoopRecord.__dataclass_fields__ if name != "T_match_query"]
LOOPS_CSV_COLUMNS = LOOPS_CSV_FIELDS + ["tx", "ty", "tz", "qx", "qy", "qz", "qw"]


@dataclass
class Check:
    """A candidate's verification: the registered pose T_match_query, the share of the query's cells
    on the match's map, the largest disagreement of the ambiguity test's rival ends (m), its starts
    that stalled at a worse fit, and why it is refused ('' for a loop)."""

    T: np.ndarray
    overlap: float = 0.0
    ambiguity_m: float = math.nan
    stalled_starts: int = 0
    reason: str = ""


def _se3(m: np.ndarray) -> Any:
    return _core.SE3.from_matrix(np.asarray(m, dtype=np.float64))


def _transform(points: np.ndarray, T: np.ndarray) -> np.ndarray:
    return (points @ T[:3, :3].T.astype(np.float32)) + T[:3, 3].astype(np.float32)


def _cell_keys(points: np.ndarray, cell_m: float) -> np.ndarray:
    """One int64 per cell of cell_m (21 bits an axis, as the voxel keys)."""
    k = np.floor(points / cell_m).astype(np.int64) + (1 << 20)
    return (k[:, 0] << 42) | (k[:, 1] << 21) | k[:, 2]


def lower_priority(niceness: int) -> None:
    """Raises the calling thread's niceness by `niceness` (Linux: a thread is a schedulable task of
    its own); nothing where that is not possible."""
    if niceness <= 0 or not hasattr(os, "setpriority"):
        return
    tid = threading.get_native_id()
    try:
        os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + niceness)
    except OSError:
        pass


def _thinned(chunks: list[np.ndarray], cell_m: float) -> np.ndarray:
    """The points of `chunks`, one per cell of cell_m (the first in it)."""
    if not chunks:
        return np.zeros((0, 3), np.float32)
    points = np.concatenate(chunks)
    _, first = np.unique(_cell_keys(points, cell_m), return_index=True)
    return points[np.sort(first)]


def vertical_drift_m(travel_m: float) -> float:
    """The height the odometry can drift over travel_m of path (VERTICAL_DRIFT_M, VERTICAL_DRIFT)."""
    return VERTICAL_DRIFT_M + VERTICAL_DRIFT * travel_m


def _yaw_offset(dx: float, dy: float, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:2, 3] = [dx, dy]
    return m


class LoopClosure:
    """Keyframes, loop detection and verification, and the pose graph of one run."""

    def __init__(self, config: Any, T_imu_lidar: Any, niceness: int = 0):
        """niceness: added to the scheduling niceness of the threads that verify (Linux: per thread),
        so that a live odometry beside them takes the cores first (LiveLoopClosure)."""
        self.config = config
        self.T_lidar_imu = np.linalg.inv(T_imu_lidar.matrix())
        self.keyframe_distance_m = config.get("loop.keyframe_distance_m")
        self.submap_length_m = config.get("loop.submap_length_m")
        self.search_radius_m = config.get("loop.search_radius_m")
        self.min_overlap = config.get("loop.min_overlap")
        self.max_ambiguity_m = config.get("loop.max_ambiguity_m")
        self.graph = PoseGraph()
        # one thread per registration (submaps are small: 5 ms on one thread, 12 ms on two), the
        # ambiguity test's registrations side by side on the run's threads
        self.stage_configs = []
        for sigma in STAGE_SIGMAS_M:
            c = _core.Config(config)
            c.set("num_threads", 1)
            c.set("threshold.initial_threshold_m", sigma)
            self.stage_configs.append(c)
        self.workers = config.get("num_threads") or os.cpu_count() or 1
        self.niceness = niceness
        self.keyframes: list[Keyframe] = []
        self.records: list[LoopRecord] = []
        self.resolution_m: float | None = None
        self.path_m = 0.0
        self.last_position: np.ndarray | None = None
        self.quiet_until_m = -math.inf  # no search before this path length (after a loop, or an ambiguous one)
        self.verify_s = 0.0
        self.graph_s = 0.0  # time in the pose graph's updates (iSAM2)

    # ---- keyframes ---------------------------------------------------------------------------
    def add(self, odo: Any, scan: Any, result: Any) -> None:
        """A scan whose pose the odometry used (FrameResult result, the LiDAR pose at its end): its
        points undistorted again with the motion the odometry used, at the export resolution."""
        if self.resolution_m is None:
            self.resolution_m = _core.export_resolution_m(odo.effective_config)
        T = result.pose.matrix()
        kf = self.keyframe_for(T, result.stamp_ns)
        if kf.export is None:
            kf.export = _core.MapExport(self.resolution_m, odo.effective_config, "")
        T_kf_lidar = np.linalg.inv(kf.T_odom) @ T
        kf.export.add(scan, result, _se3(T_kf_lidar))
        kf.scans.append((result.stamp_ns, T_kf_lidar))

    def add_registered(self, stamp_ns: int, T_lidar: np.ndarray, points: np.ndarray) -> None:
        """A scan as the online odometry registered it: its LiDAR pose T_lidar (4x4, the odometry's
        frame) and its undistorted points in that frame ((N, 3), OdometryFrame.registered_points).
        resolution_m must be set (the segments are thinned to it when they close)."""
        kf = self.keyframe_for(T_lidar, stamp_ns)
        G_inv = np.linalg.inv(kf.T_odom)
        kf.chunks.append(_transform(np.asarray(points, dtype=np.float32), G_inv))
        kf.scans.append((stamp_ns, G_inv @ T_lidar))

    def keyframe_for(self, T: np.ndarray, stamp_ns: int) -> Keyframe:
        """The keyframe a scan at the odometry's LiDAR pose T belongs to: the current one, or a new
        one (the current segment closed and searched) once T is keyframe_distance_m from it."""
        if self.last_position is not None:
            self.path_m += float(np.linalg.norm(T[:3, 3] - self.last_position))
        self.last_position = T[:3, 3].copy()
        kf = self.keyframes[-1] if self.keyframes else None
        if kf is None or np.linalg.norm(T[:3, 3] - kf.T_odom[:3, 3]) > self.keyframe_distance_m:
            kf = self.start_keyframe(T, stamp_ns)
        return kf

    def start_keyframe(self, T: np.ndarray, stamp_ns: int) -> Keyframe:
        """Closes the current keyframe's segment (and searches for its loop), then starts one at T."""
        if self.keyframes:
            self.close_segment()
        previous = self.keyframes[-1] if self.keyframes else None
        kf = Keyframe(T, self.path_m, stamp_ns)
        self.keyframes.append(kf)
        start = time.perf_counter()
        self.graph.add_keyframe(T, self.path_m - previous.path_m if previous else 0.0)
        self.graph_s += time.perf_counter() - start
        return kf

    def close_segment(self) -> None:
        kf = self.keyframes[-1]
        if kf.export is not None:
            kf.points = np.asarray(kf.export.points().points, dtype=np.float32)
        else:
            kf.points = _thinned(kf.chunks, self.resolution_m)
        kf.export, kf.chunks = None, []
        self.search(len(self.keyframes) - 1)

    def submap(self, k: int, first: int, last: int) -> np.ndarray:
        """Segments first..last (complete ones) in keyframe k's frame (its global estimate)."""
        G_k_inv = np.linalg.inv(self.graph.pose(k))
        parts = []
        for j in range(max(0, first), min(last, len(self.keyframes) - 1) + 1):
            kf = self.keyframes[j]
            if kf.points is None or len(kf.points) == 0:
                continue
            parts.append(_transform(kf.points, G_k_inv @ self.graph.pose(j)))
        return np.concatenate(parts) if parts else np.zeros((0, 3), np.float32)

    def segments_back(self, k: int) -> int:
        """The first keyframe of k's submap: the segments within submap_length_m of path before k."""
        j = k
        while j > 0 and self.keyframes[k].path_m - self.keyframes[j - 1].path_m <= self.submap_length_m:
            j -= 1
        return j

    # ---- detection and verification ----------------------------------------------------------
    def search(self, k: int) -> None:
        """Looks for the place keyframe k revisits and verifies the nearest candidate."""
        query = self.keyframes[k]
        if query.path_m < self.quiet_until_m:
            return
        G = self.graph.poses()
        best, best_d = None, math.inf
        for j in range(k):
            travel = query.path_m - self.keyframes[j].path_m
            if travel < MIN_LOOP_TRAVEL_FACTOR * self.submap_length_m:
                break
            d = float(np.linalg.norm(G[k][:3, 3] - G[j][:3, 3]))
            level = abs(G[k][2, 3] - G[j][2, 3]) <= vertical_drift_m(travel)
            if level and d <= self.search_radius_m + SEARCH_DRIFT * travel and d < best_d:
                best, best_d = j, d
        if best is not None:
            self.verify(k, best, best_d)

    def register(self, source: np.ndarray, target: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, int]:
        """T_target_source by GICP, coarse to fine from guess, and the last stage's inliers."""
        src, tgt = farlio.Scan(source), farlio.Scan(target)
        T, inliers = guess, 0
        for c in self.stage_configs:
            result = _core.register_pair(src, tgt, _se3(T), c)
            T, inliers = result.pose.matrix(), result.inliers
        return T, inliers

    def check(self, k: int, j: int, guess: np.ndarray) -> Check:
        """Registers keyframe k's submap onto j's neighbourhood from guess (T_j_k): the pose found,
        the overlap, the ambiguity and why it is refused ('' when it is a loop)."""
        source = self.submap(k, self.segments_back(k), k)
        j_first = self.segments_back(j)
        target = self.submap(j, j_first, j + (j - j_first))
        T, inliers = self.register(source, target, guess)
        if not np.all(np.isfinite(T)):
            return Check(T, reason="registration failed")
        overlap = self.overlap(_transform(source, T), target)
        if overlap < self.min_overlap:
            return Check(T, overlap, reason=f"overlap {overlap:.2f} < loop.min_overlap {self.min_overlap}")
        ambiguity, stalled = self.ambiguity(source, target, T, inliers)
        if ambiguity > self.max_ambiguity_m:
            return Check(T, overlap, ambiguity, stalled, f"{AMBIGUOUS}: starts nearby end {ambiguity:.2f} m apart")
        return Check(T, overlap, ambiguity, stalled)

    def verify(self, k: int, j: int, distance_m: float) -> None:
        """Checks the candidate from the graph's guess; a loop edge when it passes and the graph does
        not already agree with it (a loop within its own std of the estimate would only add its
        error: the handheld walk's odometry is within 1 cm where a loop is within a few)."""
        start = time.perf_counter()
        guess = np.linalg.inv(self.graph.pose(j)) @ self.graph.pose(k)
        c = self.check(k, j, guess)
        T, reason = c.T, c.reason
        travel = self.keyframes[k].path_m - self.keyframes[j].path_m
        rise_m = float((self.graph.pose(j) @ T)[2, 3] - self.graph.pose(k)[2, 3]) if not reason else 0.0
        if abs(rise_m) > (drift_m := vertical_drift_m(travel)):
            reason = f"height corrected by {rise_m:.2f} m, beyond the {drift_m:.2f} m the odometry drifts"
            reason += f" over {travel:.0f} m (another level?)"
        correction = np.linalg.inv(guess) @ T if np.all(np.isfinite(T)) else np.full((4, 4), np.nan)
        finite = bool(np.all(np.isfinite(correction)))
        correction_m = float(np.linalg.norm(correction[:3, 3]))
        correction_rad = _se3(correction).angle_rad() if finite else math.nan
        if reason.startswith(AMBIGUOUS):
            self.quiet_until_m = self.keyframes[k].path_m + RETRY_AFTER_AMBIGUOUS * self.submap_length_m
        in_graph = not reason and not (correction_m < LOOP_SIGMA[0] and correction_rad < LOOP_SIGMA[1])
        if in_graph:
            cov = np.diag([LOOP_SIGMA[1] ** 2] * 3 + [LOOP_SIGMA[0] ** 2] * 3)
            graph_start = time.perf_counter()
            self.graph.add_loop(j, k, T, cov)
            self.graph_s += time.perf_counter() - graph_start
        if not reason:
            self.quiet_until_m = self.keyframes[k].path_m + self.submap_length_m
        elapsed = time.perf_counter() - start
        self.verify_s += elapsed
        self.records.append(
            LoopRecord(
                k,
                j,
                self.keyframes[k].stamp_ns,
                self.keyframes[j].stamp_ns,
                distance_m,
                c.overlap,
                correction_m,
                math.degrees(correction_rad),
                c.ambiguity_m,
                c.stalled_starts,
                not reason,
                in_graph,
                reason,
                elapsed,
                T,
            )
        )

    def overlap(self, source_in_target: np.ndarray, target: np.ndarray) -> float:
        """The fraction of the source's cells that the target occupies too."""
        if len(source_in_target) == 0:
            return 0.0
        cell = OVERLAP_CELL_FACTOR * self.resolution_m
        s = np.unique(_cell_keys(source_in_target, cell))
        return float(np.isin(s, np.unique(_cell_keys(target, cell))).mean())

    def ambiguity(self, source: np.ndarray, target: np.ndarray, T: np.ndarray, inliers: int) -> tuple[float, int]:
        """The largest distance from T (found with `inliers`) of the registrations started around it
        that fit about as well (their rival ends), and how many starts ended at a clearly worse fit."""
        starts = [
            T @ _yaw_offset(dx, dy, yaw)
            for dx, dy, yaw in (
                (AMBIGUITY_OFFSET_M, 0.0, AMBIGUITY_YAW_RAD),
                (-AMBIGUITY_OFFSET_M, 0.0, -AMBIGUITY_YAW_RAD),
                (0.0, AMBIGUITY_OFFSET_M, -AMBIGUITY_YAW_RAD),
                (0.0, -AMBIGUITY_OFFSET_M, AMBIGUITY_YAW_RAD),
            )
        ]
        # register_pair releases the GIL
        with ThreadPoolExecutor(self.workers, initializer=lower_priority, initargs=(self.niceness,)) as pool:
            ends = list(pool.map(lambda start: self.register(source, target, start), starts))
        worst, stalled = 0.0, 0
        for Ti, end_inliers in ends:
            if not np.all(np.isfinite(Ti)):
                return math.inf, stalled
            turned_rad = _se3(np.linalg.inv(T) @ Ti).angle_rad()
            if turned_rad > AMBIGUITY_STALLED_TURN * AMBIGUITY_YAW_RAD and end_inliers < AMBIGUITY_MIN_FIT * inliers:
                stalled += 1
                continue
            worst = max(worst, float(np.linalg.norm(Ti[:3, 3] - T[:3, 3])))
        return worst, stalled

    # ---- results ------------------------------------------------------------------------------
    def finish(self) -> None:
        """Closes the last segment (and searches for its loop)."""
        if self.keyframes and self.keyframes[-1].points is None:
            self.close_segment()

    def map_from_odometry(self) -> np.ndarray:
        """The correction from the odometry's frame to the global one (REP 105's map -> odom), 4x4:
        the newest keyframe's global pose times the inverse of its odometry pose."""
        if not self.keyframes:
            return np.eye(4)
        k = len(self.keyframes) - 1
        return self.graph.pose(k) @ np.linalg.inv(self.keyframes[k].T_odom)

    def global_lidar_poses(self) -> list[tuple[int, np.ndarray]]:
        """Every scan's LiDAR pose in the global frame (its keyframe's optimised pose)."""
        out = []
        for k, kf in enumerate(self.keyframes):
            G = self.graph.pose(k)
            out.extend((stamp, G @ T_kf) for stamp, T_kf in kf.scans)
        return out

    def accepted_loop_ends(self) -> np.ndarray:
        """(M, 2, 2): the global xy of both keyframes of every accepted loop (map_global.png)."""
        ends = [[self.graph.pose(r.query)[:2, 3], self.graph.pose(r.match)[:2, 3]] for r in self.records if r.accepted]
        return np.asarray(ends, dtype=np.float64).reshape(-1, 2, 2)

    def global_points(self) -> np.ndarray:
        """Every segment's points at its keyframe's global pose (the rebuilt map's input)."""
        parts = [
            _transform(kf.points, self.graph.pose(k)) for k, kf in enumerate(self.keyframes) if kf.points is not None
        ]
        return np.concatenate(parts) if parts else np.zeros((0, 3), np.float32)

    def write(self, out_dir: Path) -> dict[str, Any]:
        """scans_lidar_global.tum, scans_body_global.tum, loops.csv; returns the summary's entry."""
        lidar = _core.io.TrajectoryWriter(Path(out_dir) / SCANS_LIDAR_GLOBAL_TUM)
        body = _core.io.TrajectoryWriter(Path(out_dir) / SCANS_BODY_GLOBAL_TUM)
        for stamp, T in self.global_lidar_poses():
            lidar.append(stamp, _se3(T))
            body.append(stamp, _se3(T @ self.T_lidar_imu))
        with open(Path(out_dir) / LOOPS_CSV, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(LOOPS_CSV_COLUMNS)
            for r in self.records:
                w.writerow(r.row())
        accepted = [r for r in self.records if r.accepted]
        return {
            "keyframes": len(self.keyframes),
            "path_m": self.path_m,
            "candidates": len(self.records),
            "accepted": len(accepted),
            "in_graph": sum(r.in_graph for r in accepted),
            "verify_s": self.verify_s,
            "graph_s": self.graph_s,
            "largest_correction_m": max((r.correction_m for r in accepted), default=0.0),
        }
