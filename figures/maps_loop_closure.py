#!/usr/bin/env python3
"""Loop closure against the ground truth (docs/maps.md, "Loop closure: figures"): `farlio run
--loop-closure` (run_dataset, scans generated in memory, fixed 20 ms replay latency) per seed,
printing

  odometry / global APE   aligned translation RMSE of scans_body.tum / scans_body_global.tum (m)
  accepted (in graph) / verified  loops accepted (of which added to the pose graph: the others agreed
                          with its estimate within the loop edge's std) and candidates verified
  precision               accepted loops whose registered pose (loops.csv tx..qw) is within
                          CORRECT_LOOP_M and CORRECT_LOOP_DEG of the ground truth's relative pose
  recall                  the revisited path (scans within REVISIT_M, REVISIT_HEIGHT_M of where the truth was
                          at least 2 submap lengths earlier) that lies within loop.submap_length_m
                          of an accepted loop's query keyframe
  verify s, graph s        time spent verifying candidates, and in the pose graph's updates (iSAM2)
  along / across / up m   the global trajectory's error after the APE's alignment, RMS along the
                          body's axes (x forward, y left, z up of the true pose); then the same of
                          the odometry's scan poses

With --walls, instead: how thick the rebuilt map's surfaces are. The map of every keyframe's
segment (one centroid per WALL_RESOLUTION_M cell) is rebuilt at three sets of poses: the first
pass only (the keyframes before the truth first revisits a place), and the whole run at its
odometry and at its global poses. Each set of poses is aligned to the truth as the APE aligns
them, and WALL_POINTS of the map's points are measured against the scene's true surfaces: the
median and 90th percentile of the distance, and the share beyond WALL_FAR_M. A second pass that
sits beside the first widens the surfaces; one that lies on it does not.

With --handover, instead: keyframes HANDOVER_SEPARATION_M apart along the path (every
HANDOVER_STRIDE-th keyframe against the first one far enough back) are handed to the verification
as if they were one place (guess: identity), and each pair's overlap, the distance between the
ambiguity test's ends and the verdict are printed, with the error of the registered pose against
the ground truth's relative pose: repeated structure must be refused or found where it truly is.

Usage: python figures/maps_loop_closure.py [--profile racetrack] [--duration 165] [--seeds 1 2 3]
       [--lidar MODEL] [--lidar-rate HZ] [--set name=value ...] [--out DIR] [--handover | --walls]
The racetrack's first lap takes 82.7 s: 165 s is two laps (8.3 km).
"""

from __future__ import annotations

import argparse
import csv
import math
import tempfile
from pathlib import Path

import numpy as np
from farlio import _core
from farlio.evaluation import make_options
from farlio.loop_closure import LOOPS_CSV, MIN_LOOP_TRAVEL_FACTOR, SCANS_BODY_GLOBAL_TUM, LoopClosure
from farlio.mapping import MapOptions, downsample
from farlio.runner import SCANS_BODY_TUM
from harness import GeneratedDataset, ape_m, config, fixed_latency, generated_dataset, run, table_row
from scipy.spatial.transform import Rotation  # xyzw quaternions, as loops.csv

CORRECT_LOOP_M, CORRECT_LOOP_DEG = 0.5, 1.0
#: a revisit: within REVISIT_M horizontally and REVISIT_HEIGHT_M vertically (a garage's levels are 3.2 m apart)
REVISIT_M, REVISIT_HEIGHT_M = 5.0, 1.5
HANDOVER_SEPARATION_M, HANDOVER_STRIDE = (60.0, 200.0), 10
#: the rebuilt maps' surfaces (--walls): points drawn from each map, its cells, and "far" from a surface
WALL_POINTS, WALL_RESOLUTION_M, WALL_FAR_M = 100_000, 0.2, 0.2
WALL_COLUMNS = ("seed", "map", "keyframes", "median m", "90th percentile m", "beyond 0.2 m")
#: the columns of a handed-over pair
HANDOVER_COLUMNS = (
    "query",
    "match",
    "separation m",
    "overlap",
    "ambiguity m",
    "stalled starts",
    "error vs truth m",
    "verdict",
)
#: the columns of a run's row
COLUMNS = (
    "seed",
    "odometry APE m",
    "global APE m",
    "accepted (in graph) / verified",
    "precision",
    "recall",
    "verify s",
    "graph s",
    "along / across / up m",
    "odometry along / across / up m",
)


def gt_lidar(gen) -> tuple[np.ndarray, list[np.ndarray]]:
    T_il = gen.T_imu_lidar().matrix()
    gt = gen.groundtruth_scans()
    return np.array([s for s, _ in gt]), [p.matrix() @ T_il for _, p in gt]


def revisited(poses: list[np.ndarray], submap_length_m: float) -> tuple[np.ndarray, np.ndarray]:
    """The path length (m) at each true pose, and whether it lies within REVISIT_M horizontally and
    REVISIT_HEIGHT_M vertically of where the truth was at least MIN_LOOP_TRAVEL_FACTOR submap lengths
    of path earlier."""
    P = np.array([p[:3, 3] for p in poses])
    path = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))]
    min_travel = MIN_LOOP_TRAVEL_FACTOR * submap_length_m
    revisit = np.zeros(len(P), bool)
    for i in range(len(P)):
        earlier = path < path[i] - min_travel
        near = (np.linalg.norm(P[earlier, :2] - P[i, :2], axis=1) < REVISIT_M) & (
            np.abs(P[earlier, 2] - P[i, 2]) < REVISIT_HEIGHT_M
        )
        revisit[i] = bool(near.any())
    return path, revisit


def precision_recall(gen, loops_csv: Path, submap_length_m: float) -> tuple[float, float]:
    stamps, poses = gt_lidar(gen)

    def at(stamp: int) -> np.ndarray:
        return poses[min(int(np.searchsorted(stamps, stamp)), len(poses) - 1)]

    with open(loops_csv) as f:
        accepted = [r for r in csv.DictReader(f) if r["accepted"] == "True"]
    correct = 0
    for r in accepted:
        m = np.eye(4)
        m[:3, :3] = Rotation.from_quat([float(r[k]) for k in ("qx", "qy", "qz", "qw")]).as_matrix()
        m[:3, 3] = [float(r[k]) for k in ("tx", "ty", "tz")]
        true = np.linalg.inv(at(int(r["match_stamp_ns"]))) @ at(int(r["query_stamp_ns"]))
        d = _core.SE3.from_matrix(np.linalg.inv(true) @ m)
        deg = math.degrees(d.angle_rad())
        correct += int(np.linalg.norm(d.translation) < CORRECT_LOOP_M and deg < CORRECT_LOOP_DEG)
    path, revisit = revisited(poses, submap_length_m)
    query_path = [path[min(int(np.searchsorted(stamps, int(r["query_stamp_ns"]))), len(path) - 1)] for r in accepted]
    covered = np.array([any(abs(path[i] - q) <= submap_length_m for q in query_path) for i in np.flatnonzero(revisit)])
    precision = correct / len(accepted) if accepted else math.nan
    recall = float(covered.mean()) if len(covered) else math.nan
    return precision, recall


def error_axes(gen, tum: Path) -> np.ndarray:
    """RMS (m) along the true body's x, y, z of the error of a body trajectory after the APE's
    alignment (the evaluation's own, without scale)."""
    truth = _core.Trajectory()
    for stamp, pose in gen.groundtruth_scans():
        truth.push_back(stamp, pose)
    est = _core.io.read_trajectory(tum)
    align = _core.eval.evaluate(est, truth, make_options()).ape.alignment.transform
    true_pose = {truth[i][0]: truth[i][1] for i in range(len(truth))}
    body = [
        true_pose[s].rotation().T @ ((align * p).translation - true_pose[s].translation)
        for s, p in (est[i] for i in range(len(est)))
        if s in true_pose
    ]
    return np.sqrt((np.array(body) ** 2).mean(axis=0))


def closed_loops(ds: GeneratedDataset, cfg) -> LoopClosure:
    """The odometry over the dataset (fixed latency) with the loop closure beside it, in process."""
    odo = _core.Odometry(cfg, ds.T_imu_lidar(), ds.gravity_m_s2(), ds.imu(), fixed_latency())
    loops = LoopClosure(cfg, ds.T_imu_lidar())
    for i in range(len(ds)):
        scan = ds.scan(i)
        fr = odo.process(scan)
        if fr.processed and not fr.scan.failure:
            loops.add(odo, scan, fr.scan)
    loops.finish()
    return loops


def surface_distances(
    gen, truth: tuple[np.ndarray, list[np.ndarray]], loops: LoopClosure, poses: list[np.ndarray], resolution_m: float
) -> np.ndarray:
    """|distance| (m) to the scene's nearest true surface of WALL_POINTS points (a fixed draw) of
    the map of the first len(poses) keyframes' segments at these LiDAR poses, one centroid per cell,
    after the APE's alignment of the poses to the truth's (gt_lidar; the evaluation's own, without
    scale)."""
    truth_stamps, truth_poses = truth
    est, ref = _core.Trajectory(), _core.Trajectory()
    for kf, pose in zip(loops.keyframes, poses):
        true_pose = truth_poses[min(int(np.searchsorted(truth_stamps, kf.stamp_ns)), len(truth_poses) - 1)]
        est.push_back(kf.stamp_ns, _core.SE3.from_matrix(pose))
        ref.push_back(kf.stamp_ns, _core.SE3.from_matrix(true_pose))
    align = _core.eval.evaluate(est, ref, make_options()).ape.alignment.transform.matrix()
    # in double: the map's points as measured, not as LoopClosure stores them (float32)
    parts = [kf.points @ T[:3, :3].T + T[:3, 3] for kf, T in zip(loops.keyframes, poses) if kf.points is not None]
    points = downsample(np.concatenate(parts).astype(np.float64), resolution_m)
    rng = np.random.default_rng(0)
    points = points[rng.choice(len(points), min(WALL_POINTS, len(points)), replace=False)]
    world = points @ align[:3, :3].T + align[:3, 3]
    return np.abs(np.asarray(gen.surface_distance_m(world)))


def walls(ds: GeneratedDataset, cfg, seed: int) -> None:
    """How thick the rebuilt map's surfaces are (see the module doc)."""
    loops = closed_loops(ds, cfg)
    kfs = loops.keyframes
    truth = gt_lidar(ds.gen)
    stamps, poses = truth
    _, revisit = revisited(poses, cfg.get("loop.submap_length_m"))
    first_revisit_ns = stamps[np.argmax(revisit)] if revisit.any() else stamps[-1]
    first_pass = sum(1 for kf in kfs if kf.stamp_ns <= first_revisit_ns)  # the keyframes come in time order
    odometry = [kf.T_odom for kf in kfs]
    maps = {
        "one pass, odometry": odometry[:first_pass],
        "all, odometry": odometry,
        "all, global": [loops.graph.pose(k) for k in range(len(kfs))],
    }
    for name, kf_poses in maps.items():
        d = surface_distances(ds.gen, truth, loops, kf_poses, WALL_RESOLUTION_M)
        cells = [f"{np.median(d):.3f}", f"{np.percentile(d, 90):.3f}", f"{np.mean(d > WALL_FAR_M):.3f}"]
        print(table_row(seed, name, len(kf_poses), *cells), flush=True)


def handover(ds: GeneratedDataset, cfg) -> None:
    """Different places handed over as one (see the module doc)."""
    loops = closed_loops(ds, cfg)
    stamps, poses = gt_lidar(ds.gen)

    def at(stamp: int) -> np.ndarray:
        return poses[min(int(np.searchsorted(stamps, stamp)), len(poses) - 1)]

    kfs = loops.keyframes
    print(f"{len(kfs)} keyframes, {sum(r.accepted for r in loops.records)} loops accepted in the run")
    print(table_row(*HANDOVER_COLUMNS))
    for k in range(0, len(kfs), HANDOVER_STRIDE):
        far = [j for j in range(k) if HANDOVER_SEPARATION_M[0] <= kfs[k].path_m - kfs[j].path_m]
        far = [j for j in far if kfs[k].path_m - kfs[j].path_m <= HANDOVER_SEPARATION_M[1]]
        if not far:
            continue
        j = far[-1]
        c = loops.check(k, j, np.eye(4))
        error = np.linalg.norm((np.linalg.inv(np.linalg.inv(at(kfs[j].stamp_ns)) @ at(kfs[k].stamp_ns)) @ c.T)[:3, 3])
        separation = kfs[k].path_m - kfs[j].path_m
        cells = (f"{separation:.0f}", f"{c.overlap:.2f}", f"{c.ambiguity_m:.2f}", c.stalled_starts, f"{error:.2f}")
        print(table_row(k, j, *cells, c.reason or "accepted"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", default="racetrack")
    ap.add_argument("--duration", type=float, default=165.0)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--lidar", default="profile")
    ap.add_argument("--lidar-rate", type=float, default=None)
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--handover", action="store_true", help="different places handed over as one (module doc)")
    ap.add_argument("--walls", action="store_true", help="how thick the rebuilt maps' surfaces are (module doc)")
    args = ap.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="measure_loops_"))
    cfg = config(args.set)
    if args.walls:
        print(table_row(*WALL_COLUMNS))
        for seed in args.seeds:
            ds = generated_dataset(
                args.profile, seed, args.duration, out, lidar=args.lidar, lidar_rate_hz=args.lidar_rate
            )
            walls(ds, cfg, seed)
        return
    if args.handover:
        for seed in args.seeds:
            handover(
                generated_dataset(
                    args.profile, seed, args.duration, out, lidar=args.lidar, lidar_rate_hz=args.lidar_rate
                ),
                cfg,
            )
        return
    print(table_row(*COLUMNS))
    for seed in args.seeds:
        ds = generated_dataset(args.profile, seed, args.duration, out, lidar=args.lidar, lidar_rate_hz=args.lidar_rate)
        s = run(ds, out / f"run-{seed}", cfg, MapOptions(loop_closure=True))
        lc = s["loop_closure"]
        precision, recall = precision_recall(ds.gen, out / f"run-{seed}" / LOOPS_CSV, cfg.get("loop.submap_length_m"))
        cells = [f"{ape_m(s['accuracy']):.3f}", f"{ape_m(s['accuracy_global']):.3f}"]
        cells += [f"{lc['accepted']} ({lc['in_graph']}) / {lc['candidates']}", f"{precision:.2f}", f"{recall:.2f}"]
        axes = [
            " / ".join(f"{v:.2f}" for v in error_axes(ds.gen, out / f"run-{seed}" / name))
            for name in (SCANS_BODY_GLOBAL_TUM, SCANS_BODY_TUM)
        ]
        print(table_row(seed, *cells, f"{lc['verify_s']:.1f}", f"{lc['graph_s']:.2f}", *axes), flush=True)
    print(f"outputs in {out}")


if __name__ == "__main__":
    main()
