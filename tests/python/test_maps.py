"""Maps: the whole map of a run (--save-map) lies on the generator's surfaces, and a
second pass over the same scene (another noise seed) localized in it (--prior-map) follows the map
without drift, while its own odometry drifts away from it; a wrong initial pose is reported as not
localized."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from farlio import _core
from farlio.cli import main as cli
from farlio.config import load_config
from farlio.datasets import open_dataset
from farlio.mapping import MapOptions, pose_from_xyz_rpy_deg
from farlio.runner import replay_options, run_dataset
from farlio.simulation import generate, make_config

PROFILE, DURATION_S = "urban", 12.0
MAP_SEED, PASS_SEED = 1, 2
# map points: the centroid of a cell of 0.63 m on a plane lies on it; at edges and on round
# things it lies inside; the odometry drifts ~1 cm over the run
MEDIAN_SURFACE_DISTANCE_M, P90_SURFACE_DISTANCE_M = 0.03, 0.15
# localization: the pose against the mapping run's at the same stamp (the map's own frame)
LOCALIZED_END_ERROR_M, LOCALIZED_MAX_ERROR_M = 0.05, 0.10
# a localized scan matches most of its points (0.97..0.99 in urban and handheld)
LOCALIZED_MIN_INLIER_FRACTION = 0.95


def _run(seq: Path, out: Path, maps: MapOptions | None = None, fused: bool = True) -> dict:
    config = load_config(None, [] if fused else ["fusion.enabled=false"])
    return run_dataset(
        open_dataset(seq), out, config, progress=False, plot=False, maps=maps, options=replay_options("fixed", 0.02)
    )


def _poses(path: Path) -> dict[int, np.ndarray]:
    t = _core.io.read_trajectory(path)
    return {t[i][0]: t[i][1].matrix() for i in range(len(t))}


def _errors(estimate: dict[int, np.ndarray], reference: dict[int, np.ndarray]) -> np.ndarray:
    """Position error of every stamp both have, in stamp order."""
    return np.array(
        [np.linalg.norm(estimate[s][:3, 3] - reference[s][:3, 3]) for s in sorted(estimate) if s in reference]
    )


@pytest.fixture(scope="module")
def mapped(tmp_path_factory):
    """The mapping run (seed 1, --save-map) and a second pass over the same scene (seed 2)."""
    root = tmp_path_factory.mktemp("maps")
    generate(PROFILE, root / "map_seq", duration_s=DURATION_S, seed=MAP_SEED)
    generate(PROFILE, root / "pass_seq", duration_s=DURATION_S, seed=PASS_SEED)
    summary = _run(root / "map_seq", root / "mapping", MapOptions(save=True))
    return root, summary


def test_saved_map_lies_on_the_scene(mapped):
    root, summary = mapped
    out = root / "mapping"
    cloud = _core.io.read_point_cloud(out / "map.pcd")
    points = np.asarray(cloud.points, dtype=np.float64)
    assert summary["map"]["points"] == len(points) > 20000
    assert np.array_equal(points, np.asarray(_core.io.read_point_cloud(out / "map.ply").points, dtype=np.float64))
    assert len(cloud.intensity) == len(points) and np.ptp(np.asarray(cloud.intensity)) > 0  # intensity kept
    # the whole map reaches beyond the submap's radius is not the point here (urban: 1000 m); it
    # holds every place the run saw: the first scan's surroundings and the last's
    poses = _poses(out / "scans_lidar.tum")
    first, last = (poses[s][:3, 3] for s in (min(poses), max(poses)))
    for p in (first, last):
        assert (np.linalg.norm(points[:, :2] - p[:2], axis=1) < 10.0).sum() > 100
    # into the generator's frame: the odometry's world differs from it by the attitude found at the
    # start (roll and pitch from gravity), i.e. by T_gt_est at the first scan
    gt, est = _poses(root / "map_seq" / "groundtruth_scans.tum"), _poses(out / "scans_body.tum")
    s0 = min(est)
    T = gt[s0] @ np.linalg.inv(est[s0])
    sample = points[np.random.default_rng(0).choice(len(points), 3000, replace=False)]
    world = sample @ T[:3, :3].T + T[:3, 3]
    gen = _core.sim.SequenceGenerator(make_config(PROFILE, seed=MAP_SEED, duration_s=DURATION_S))
    d = np.asarray(gen.surface_distance_m(world))
    assert np.median(d) < MEDIAN_SURFACE_DISTANCE_M, np.median(d)
    assert np.percentile(d, 90) < P90_SURFACE_DISTANCE_M, np.percentile(d, 90)


def test_map_memory_does_not_grow_on_a_revisit(mapped):
    """Adding every scan of the run a second time (a second lap over the same road) adds no cell."""
    root, _ = mapped
    seq = open_dataset(root / "map_seq")
    config = load_config(None, [])
    odo = _core.Odometry(config, seq.T_imu_lidar(), seq.gravity_m_s2(), [], replay_options("zero"))
    export = None
    frames = []
    for i in range(0, len(seq), 4):
        scan = seq.scan(i)
        frame = odo.process(scan)
        frames.append((scan, frame.scan))
        if export is None:
            export = _core.MapExport(_core.export_resolution_m(odo.effective_config), odo.effective_config)
        export.add(scan, frame.scan)
    cells, memory = export.cells, export.memory_bytes
    for scan, result in frames:
        export.add(scan, result)
    assert export.cells == cells and export.memory_bytes == memory


@pytest.mark.parametrize("fused", [True, False], ids=["lio", "lidar_only"])
def test_localization_follows_the_map_without_drift(mapped, fused):
    root, _ = mapped
    prior = root / "mapping" / "map.pcd"
    loc = _run(root / "pass_seq", root / f"loc_{fused}", MapOptions(prior_map=prior), fused=fused)
    odo = _run(root / "pass_seq", root / f"odo_{fused}", fused=fused)
    assert loc["localization"]["frames_lost"] == 0 and loc["localization"]["localized"]
    with open(root / f"loc_{fused}" / "timing.csv") as f:
        rows = list(csv.DictReader(f))
    assert min(float(r["inlier_fraction"]) for r in rows) > LOCALIZED_MIN_INLIER_FRACTION
    assert all(r["lost"] == "0" for r in rows)
    # in the map's frame the mapping run's pose at the same stamp is where the scan belongs
    mapping = _poses(root / "mapping" / "scans_body.tum")
    loc_err = _errors(_poses(root / f"loc_{fused}" / "scans_body.tum"), mapping)
    odo_err = _errors(_poses(root / f"odo_{fused}" / "scans_body.tum"), mapping)
    assert len(loc_err) >= 0.9 * DURATION_S * 10
    assert loc_err[-1] < LOCALIZED_END_ERROR_M and loc_err.max() < LOCALIZED_MAX_ERROR_M, (loc_err[-1], loc_err.max())
    assert odo_err[-1] > 2 * loc_err[-1], (odo_err[-1], loc_err[-1])  # the odometry alone drifts off the map
    # against the ground truth (aligned) localization is as good as the odometry: the map's accuracy
    ape = loc["accuracy"]["ape"]["translation_m"]["rmse"]
    assert ape <= odo["accuracy"]["ape"]["translation_m"]["rmse"] + 0.005


def test_initial_pose_off_by_half_a_metre_localizes(mapped):
    root, _ = mapped
    out = root / "loc_offset"
    maps = MapOptions(prior_map=root / "mapping" / "map.pcd", initial_pose=[0.5, -0.3, 0.0, 0.0, 0.0, 2.0])
    summary = _run(root / "pass_seq", out, maps)
    assert summary["localization"]["localized"] and summary["localization"]["localized_at_end"]
    err = _errors(_poses(out / "scans_body.tum"), _poses(root / "mapping" / "scans_body.tum"))
    assert err[-1] < LOCALIZED_END_ERROR_M, err[-1]


def test_wrong_initial_pose_is_not_localized(mapped, capsys):
    root, _ = mapped
    out = root / "loc_wrong"
    code = cli(
        ["run", str(root / "pass_seq"), "--out", str(out), "--no-progress", "--no-plot",
         "--prior-map", str(root / "mapping" / "map.pcd"), "--initial-pose", "30", "0", "0", "0", "0", "0"]
    )  # fmt: skip
    assert code == 3
    assert "not localized" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert not summary["localization"]["localized"]
    assert summary["localization"]["frames_lost"] > summary["localization"]["frames_localized"]


def test_initial_pose_text():
    T = pose_from_xyz_rpy_deg([1, 2, 3, 0, 0, 90]).matrix()
    assert np.allclose(T[:3, 3], [1, 2, 3]) and np.allclose(T[:3, 0], [0, 1, 0], atol=1e-12)
    T = pose_from_xyz_rpy_deg([0, 0, 0, 90, 0, 0]).matrix()  # roll: y goes to z
    assert np.allclose(T[:3, 1], [0, 0, 1], atol=1e-12)
    with pytest.raises(ValueError, match="X Y Z ROLL PITCH YAW"):
        pose_from_xyz_rpy_deg([0, 0, 0])
    with pytest.raises(ValueError, match="X Y Z ROLL PITCH YAW"):
        pose_from_xyz_rpy_deg([0, 0, float("nan"), 0, 0, 0])


def test_an_empty_prior_map_names_the_file(tmp_path, capsys):
    seq = tmp_path / "seq"
    generate(PROFILE, seq, duration_s=1.0)
    empty = tmp_path / "empty.pcd"
    _core.io.write_pcd(empty, _core.Scan(np.zeros((0, 3), np.float32)))
    assert cli(["run", str(seq), "--out", str(tmp_path / "o"), "--prior-map", str(empty), "--no-progress"]) == 2
    assert "empty.pcd" in capsys.readouterr().err


def test_online_odometry_localizes_as_the_replay_does(mapped):
    """OnlineOdometry.set_prior_map / set_initial_pose (the ROS 2 node's prior_map and initial_pose)
    give the replay's localization, fed in lockstep with zero latency."""
    root, _ = mapped
    ds = open_dataset(root / "pass_seq")
    scans = [ds.scan(i) for i in range(30)]
    imu, T, g = ds.imu(), ds.T_imu_lidar(), ds.gravity_m_s2()
    prior = _core.io.read_point_cloud(root / "mapping" / "map.pcd")
    start = pose_from_xyz_rpy_deg([0.3, -0.2, 0.0, 0.0, 0.0, 1.0])
    replay = _core.Odometry(load_config(None, []), T, g, imu, replay_options("zero"))
    replay.set_prior_map(prior)
    replay.set_initial_pose(start)
    expected = [replay.process(s) for s in scans]
    online = _core.OnlineOdometry(load_config(None, []), T, g)
    online.set_prior_map(prior)
    online.set_initial_pose(start)
    k = 0
    for s in scans:
        while k < len(imu) and imu[k].stamp_ns <= s.end_stamp_ns:
            online.add_imu(imu[k])
            k += 1
        assert online.add_scan(s)
        online.wait_idle()
    online.stop()
    frames = online.take_frames()
    assert len(frames) == len(scans) and not any(f.scan.lost for f in frames)
    got = np.array([f.body_pose.translation for f in frames])
    assert np.abs(got - np.array([e.body_pose.translation for e in expected])).max() < 1e-6
    with pytest.raises(RuntimeError, match="after the first scan"):
        online.set_initial_pose(start)
