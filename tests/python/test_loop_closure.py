"""Loop closure (farlio run --loop-closure): on the racetrack's second lap (Ouster OS-128 model at
10 Hz, seed 1, in memory) the revisited places are found and every accepted loop agrees with the
ground truth; places that are not the same (keyframes 60-200 m apart on the racetrack's first lap
and in the tunnel, whose walls repeat, handed over as if they were one place) are never accepted as
a loop at a wrong pose, and the tunnel closes no loop; the global trajectory is closer to the
ground truth than the odometry's; in a parking garage whose levels look alike, no level is closed
onto the one below, though the registration alone would; the live back end does the same beside
the online odometry, on threads that yield to it; the handheld walk's return is found without
moving a trajectory that did not drift; the CLI writes the global trajectories and loops.csv."""

from __future__ import annotations

import csv
import math
import os
import threading
import time

import numpy as np
import pytest

pytest.importorskip("gtsam")

from farlio import _core  # noqa: E402
from farlio.evaluation import make_options  # noqa: E402
from farlio.loop_closure import (  # noqa: E402
    LOOPS_CSV,
    MIN_LOOP_TRAVEL_FACTOR,
    SCANS_BODY_GLOBAL_TUM,
    LoopClosure,
)
from farlio.runner import replay_options  # noqa: E402
from farlio.simulation import make_config  # noqa: E402

#: the first lap takes 82.7 s: 100 s revisits its first 1.2 km
DURATION_S = 100.0
#: an accepted loop agrees with the ground truth's relative pose within this (m, deg)
LOOP_TOLERANCE = (0.5, 1.0)
#: wrong-place pairs: keyframes this far apart along the path (m)
WRONG_PLACE_SEPARATION_M = (60.0, 200.0)
#: the pairs: every STRIDE_KEYFRAMES-th keyframe of the first FIRST_PASS_M of path against an earlier one
FIRST_PASS_M, STRIDE_KEYFRAMES = 1000.0, 10
#: the handheld walk is back in its first room
HANDHELD_RETURN_S = 182.0
#: a revisiting keyframe: within this of an earlier keyframe's true position (m)
REVISIT_M = 5.0
#: the share of the revisiting keyframes within a submap length of an accepted loop (measured 69 of
#: 81; the refused candidates lie on straights, where starts 4 m apart along it end 4 m apart)
MIN_CLOSED_SHARE = 0.8
#: the tunnel from its standing start to ~560 m along it
TUNNEL_DURATION_S = 30.0
#: the garage from its standing start up the first ramp and around level 1, over level 0
GARAGE_DURATION_S = 60.0
#: a keyframe over another: within ABOVE_M horizontally and more than ABOVE_HEIGHT_M higher (a level: 3.2 m)
ABOVE_M, ABOVE_HEIGHT_M = 5.0, 3.0
#: a registration on the wrong level: this far (m) from the true relative pose
WRONG_LEVEL_M = 2.0


def loop_run(profile: str, duration_s: float, **sim):
    """The odometry over a generated sequence with loop closure as it goes: (LoopClosure, the
    odometry's body poses, the ground truth, the ground truth's LiDAR pose at a stamp, T_lidar_imu)."""
    gen = _core.sim.SequenceGenerator(make_config(profile, duration_s=duration_s, **sim))
    config = _core.Config()
    odo = _core.Odometry(config, gen.T_imu_lidar(), gen.gravity_m_s2(), gen.imu(), replay_options("fixed", 0.02))
    loops = LoopClosure(config, gen.T_imu_lidar())
    odometry = _core.Trajectory()
    for i in range(gen.num_scans()):
        scan = gen.scan(i)
        fr = odo.process(scan)
        if fr.processed and not fr.scan.failure:
            odometry.push_back(scan.end_stamp_ns, fr.body_pose)
            loops.add(odo, scan, fr.scan)
    loops.finish()
    return loops, odometry, *truth(gen)


def truth(gen):
    """(the ground truth's scan poses, its LiDAR pose at a stamp, T_lidar_imu) of a generator."""
    gt = gen.groundtruth_scans()
    stamps = np.array([s for s, _ in gt])
    T_il = gen.T_imu_lidar().matrix()

    def gt_lidar(stamp_ns: int) -> np.ndarray:
        return gt[int(np.searchsorted(stamps, stamp_ns))][1].matrix() @ T_il

    return gt, gt_lidar, np.linalg.inv(T_il)


def assert_accepted_loops_right(loops, gt_lidar) -> list:
    """Every accepted loop's registered pose within LOOP_TOLERANCE of the truth; returns them."""
    accepted = [r for r in loops.records if r.accepted]
    for r in accepted:
        kq, km = loops.keyframes[r.query], loops.keyframes[r.match]
        true = np.linalg.inv(gt_lidar(km.stamp_ns)) @ gt_lidar(kq.stamp_ns)
        m, deg = _off(r.T_match_query, true)
        assert m < LOOP_TOLERANCE[0] and deg < LOOP_TOLERANCE[1], (r, m, deg)
    return accepted


def odometry_and_global_ape(loops, odometry, gt, T_lidar_imu) -> tuple[float, float, int]:
    """APE (m) of the odometry's body poses and of the global ones, and how many global poses."""
    glob = _core.Trajectory()
    for stamp, T in loops.global_lidar_poses():
        glob.push_back(stamp, _core.SE3.from_matrix(T @ T_lidar_imu))
    options = make_options()
    odo_ape = _core.eval.evaluate(odometry, gt, options).ape.translation_m.rmse
    glob_ape = _core.eval.evaluate(glob, gt, options).ape.translation_m.rmse
    return odo_ape, glob_ape, len(glob)


@pytest.fixture(scope="module")
def lap():
    """The racetrack's first lap and a half (OS-128 model at 10 Hz)."""
    return loop_run("racetrack", DURATION_S, lidar="os128", lidar_rate_hz=10)


@pytest.fixture(scope="module")
def tunnel():
    """The tunnel: uniform walls, the same cross-section every metre, no place revisited."""
    return loop_run("tunnel", TUNNEL_DURATION_S)


@pytest.fixture(scope="module")
def garage():
    """The garage's levels 0 and 1: identical pillars, parked cars, walls and ramps."""
    return loop_run("garage", GARAGE_DURATION_S)


def _off(T_est: np.ndarray, T_true: np.ndarray) -> tuple[float, float]:
    d = _core.SE3.from_matrix(np.linalg.inv(T_true) @ T_est)
    return float(np.linalg.norm(d.translation)), math.degrees(d.angle_rad())


def test_the_second_lap_closes_and_every_accepted_loop_is_right(lap):
    loops, _, _, gt_lidar, _ = lap
    accepted = assert_accepted_loops_right(loops, gt_lidar)
    assert len(accepted) >= 3, [(r.query, r.match, r.reason) for r in loops.records]


def test_the_revisited_path_is_closed_all_along(lap):
    """Keyframes of the second lap (within REVISIT_M of a keyframe at least two submap lengths back
    on the truth) lie within a submap length of an accepted loop: a straight's ambiguity refuses a
    loop only when a start nearby fits about as well elsewhere, not when it stalls in a local
    minimum (the starts turned by 10 deg stall at the far end of a 40 m submap)."""
    loops, _, _, gt_lidar, _ = lap
    kfs = loops.keyframes
    truth = np.array([gt_lidar(kf.stamp_ns)[:3, 3] for kf in kfs])
    path = np.array([kf.path_m for kf in kfs])
    back = MIN_LOOP_TRAVEL_FACTOR * loops.submap_length_m
    revisit = [
        k
        for k in range(len(kfs))
        if np.any(np.linalg.norm(truth[path < path[k] - back] - truth[k], axis=1) < REVISIT_M)
    ]
    queries = np.array([kfs[r.query].path_m for r in loops.records if r.accepted])
    closed = [k for k in revisit if len(queries) and np.min(np.abs(queries - path[k])) <= loops.submap_length_m]
    print(f"{len(closed)} of {len(revisit)} revisiting keyframes near an accepted loop")
    assert len(revisit) >= 50
    assert len(closed) >= MIN_CLOSED_SHARE * len(revisit)


@pytest.mark.parametrize("scene", ["lap", "tunnel"])
def test_different_places_are_never_a_loop_at_a_wrong_pose(scene, request):
    """Keyframes 60-200 m apart on the racetrack's first lap, and in the tunnel (whose walls repeat
    every metre), handed over as one place (guess: identity): refused, or found at their true
    relative pose (then the registration found the real geometry, not a wrong loop)."""
    loops, _, _, gt_lidar, _ = request.getfixturevalue(scene)
    assert not any(r.accepted for r in loops.records) or scene == "lap"  # the tunnel revisits nothing
    checked = accepted_wrong = 0
    first_pass = [k for k, kf in enumerate(loops.keyframes) if kf.path_m < FIRST_PASS_M]
    for k in first_pass[::STRIDE_KEYFRAMES]:
        for j in first_pass:
            sep = loops.keyframes[k].path_m - loops.keyframes[j].path_m
            if not WRONG_PLACE_SEPARATION_M[0] <= sep <= WRONG_PLACE_SEPARATION_M[1]:
                continue
            c = loops.check(k, j, np.eye(4))
            checked += 1
            if not c.reason:
                true = np.linalg.inv(gt_lidar(loops.keyframes[j].stamp_ns)) @ gt_lidar(loops.keyframes[k].stamp_ns)
                accepted_wrong += int(_off(c.T, true)[0] > LOOP_TOLERANCE[0])
            break
    assert checked >= 3
    assert accepted_wrong == 0


def test_a_garage_level_is_never_closed_onto_the_level_below(garage):
    """Every keyframe of level 1 that lies over a keyframe of level 0 (at least two submap lengths
    back): the search never proposes the pair (the estimate's heights differ by a level, beyond what
    the odometry drifts), and verified anyway from the graph's guess it is refused. Without that
    height check the pair would pass: the query's submap slides down onto the identical level below,
    overlapping it fully, and the ambiguity test's horizontal starts all come back to it."""
    loops, _, _, gt_lidar, _ = garage
    assert not loops.records  # nothing revisited on the same level
    kfs = loops.keyframes
    true_at = [gt_lidar(kf.stamp_ns) for kf in kfs]
    pairs = []
    for k in range(len(kfs)):
        below = [
            j
            for j in range(k)
            if kfs[k].path_m - kfs[j].path_m >= MIN_LOOP_TRAVEL_FACTOR * loops.submap_length_m
            and np.linalg.norm(true_at[k][:2, 3] - true_at[j][:2, 3]) < ABOVE_M
            and true_at[k][2, 3] - true_at[j][2, 3] > ABOVE_HEIGHT_M
        ]
        if below:
            pairs.append((k, below[-1]))
    assert len(pairs) >= 5
    slid = 0
    for k, j in pairs:
        true = np.linalg.inv(true_at[j]) @ true_at[k]
        guess = np.linalg.inv(loops.graph.pose(j)) @ loops.graph.pose(k)
        c = loops.check(k, j, guess)
        slid += int(not c.reason and _off(c.T, true)[0] > WRONG_LEVEL_M)
        loops.verify(k, j, float(np.linalg.norm(guess[:3, 3])))
        r = loops.records[-1]
        assert not r.accepted, (k, j, r)
    print(f"{slid} of {len(pairs)} level-1 keyframes pass the registration's checks on the level below")
    assert slid >= 2


def test_the_global_trajectory_is_closer_to_the_ground_truth(lap):
    loops, odometry, gt, _, T_lidar_imu = lap
    odo_ape, glob_ape, poses = odometry_and_global_ape(loops, odometry, gt, T_lidar_imu)
    assert poses == len(odometry)
    print("odometry APE", odo_ape, "global APE", glob_ape)
    assert glob_ape < 0.9 * odo_ape


def test_run_writes_the_global_trajectory_and_the_loops(tmp_path):
    """farlio run --loop-closure on a short sequence: the files exist and hold every scan."""
    from farlio.cli import main

    seq, out = tmp_path / "seq", tmp_path / "out"
    assert main(["simulate", "urban", "--out", str(seq), "--duration", "4", "--lidar", "vlp16"]) == 0
    assert main(["run", str(seq), "--out", str(out), "--loop-closure", "--save-map", "--no-plot", "--no-progress"]) == 0
    body = (out / "scans_body.tum").read_text().splitlines()
    body_global = (out / SCANS_BODY_GLOBAL_TUM).read_text().splitlines()
    assert len(body_global) == len(body) > 10
    with open(out / LOOPS_CSV) as f:
        header = next(csv.reader(f))
    assert header[:2] == ["query", "match"] and header[-7:] == ["tx", "ty", "tz", "qx", "qy", "qz", "qw"]
    assert (out / "map_global.pcd").stat().st_size > 0


def test_the_live_back_end_closes_the_lap_beside_the_online_odometry():
    """LiveLoopClosure (the ROS 2 node's loop_closure) fed with the online odometry's registered
    scans on its own thread: the second lap closes with every accepted loop right, the global
    trajectory is closer to the truth than the odometry's, and map_from_odometry maps the newest
    keyframe's odometry pose onto its global pose."""
    from farlio.live_loop_closure import LiveLoopClosure

    gen = _core.sim.SequenceGenerator(make_config("racetrack", duration_s=DURATION_S, lidar="os128", lidar_rate_hz=10))
    config = _core.Config()
    online = _core.OnlineOdometry(config, gen.T_imu_lidar(), gen.gravity_m_s2(), True)
    live = LiveLoopClosure(config, gen.T_imu_lidar(), _core.export_resolution_m(config))
    imu, k, odometry = gen.imu(), 0, _core.Trajectory()
    for i in range(gen.num_scans()):
        scan = gen.scan(i)
        while k < len(imu) and imu[k].stamp_ns <= scan.end_stamp_ns:
            online.add_imu(imu[k])
            k += 1
        assert online.add_scan(scan)
        online.wait_idle()
        for f in online.take_frames():
            if f.processed and not f.scan.failure:
                assert live.submit(f.scan.stamp_ns, f.scan.pose.matrix(), f.registered_points)
                odometry.push_back(f.scan.stamp_ns, f.body_pose)
    online.stop()
    live.stop()
    loops = live.loops
    stats = live.stats()
    assert stats.scans_dropped == 0 and stats.keyframes == len(loops.keyframes) > 100
    gt, gt_lidar, T_lidar_imu = truth(gen)
    accepted = assert_accepted_loops_right(loops, gt_lidar)
    assert len(accepted) >= 3 and stats.loops_accepted == len(accepted)
    last = loops.keyframes[-1]
    np.testing.assert_allclose(live.map_from_odometry() @ last.T_odom, loops.graph.pose(len(loops.keyframes) - 1))
    odo_ape, glob_ape, _ = odometry_and_global_ape(loops, odometry, gt, T_lidar_imu)
    print("live: odometry APE", odo_ape, "global APE", glob_ape, "loops", len(accepted), "of", len(loops.records))
    assert glob_ape < 0.9 * odo_ape


@pytest.mark.skipif(not hasattr(os, "setpriority"), reason="per-thread niceness is Linux's")
def test_the_live_back_end_runs_nicer_than_the_odometry():
    """Its thread (and the verification's, through the same lower_priority) yields the cores to the
    odometry's: niceness raised by BACK_END_NICENESS, the caller's unchanged."""
    from farlio.live_loop_closure import BACK_END_NICENESS, LiveLoopClosure

    before = os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
    live = LiveLoopClosure(_core.Config(), _core.SE3(), 0.2)
    try:
        wait_s = time.monotonic() + 5.0
        while os.getpriority(os.PRIO_PROCESS, live.native_thread_id) == before and time.monotonic() < wait_s:
            time.sleep(0.01)
        assert os.getpriority(os.PRIO_PROCESS, live.native_thread_id) == min(before + BACK_END_NICENESS, 19)
        assert os.getpriority(os.PRIO_PROCESS, threading.get_native_id()) == before
    finally:
        live.stop()


def test_loops_leave_a_walk_that_does_not_drift_as_it_was():
    """The handheld walk back through the corridor into its first room (182 s, seed 1): the return
    is found (a loop accepted, right within 0.5 m and 1 deg), and where the odometry is within a
    centimetre the loops, which agree with it within their own std, do not move the trajectory
    (global APE within 5 % of the odometry's; 0.013-0.016 m against 0.011 m when such loops were
    added)."""
    loops, odometry, gt, gt_lidar, T_lidar_imu = loop_run("handheld", HANDHELD_RETURN_S)
    assert assert_accepted_loops_right(loops, gt_lidar)
    odo_ape, glob_ape, _ = odometry_and_global_ape(loops, odometry, gt, T_lidar_imu)
    print("handheld: odometry APE", odo_ape, "global APE", glob_ape)
    assert glob_ape <= 1.05 * odo_ape


def test_a_failing_back_end_never_stops_the_odometry_side():
    """A scan the back end cannot use (points that are not (N, 3)) stops the back end, not the
    caller: submit keeps returning at once, `error` names what happened, and stop raises it."""
    from farlio.live_loop_closure import LiveLoopClosure

    live = LiveLoopClosure(_core.Config(), _core.SE3(), 0.2)
    assert live.submit(1, np.eye(4), np.zeros((10, 2), np.float32))
    assert live.submit(2, np.eye(4), np.zeros((10, 3), np.float32))
    wait_s = time.monotonic() + 5.0
    while live.error is None and time.monotonic() < wait_s:
        time.sleep(0.01)
    assert live.error is not None and "ValueError" in live.error, live.error
    assert live.submit(3, np.eye(4), np.zeros((10, 3), np.float32))
    with pytest.raises(ValueError):
        live.stop()
