"""farlio's trajectory metrics against evo (APE, RPE), kiss-icp (KITTI-style error) and numpy
brute force, on synthetic trajectories written to TUM/KITTI files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

evaluation = pytest.importorskip("farlio.evaluation")
pytest.importorskip("farlio._core")

REL_TOL = 1e-6
FRAME_PERIOD_S = 0.1
FIRST_STAMP_S = 1000.0
NOISE_SIGMA_M = 0.05
YAW_DRIFT_RAD_PER_FRAME = 2e-5
SCALE_DRIFT = 1.005
KITTI_LENGTHS_M = [100.0 * k for k in range(1, 9)]
KITTI_DEVKIT_STEP = 10
KISS_ROTATION_REL_TOL = 5e-3
#: the straight run: poses, spacing, per-pose position noise and RMS rotation error
STRAIGHT_POSES = 300
STRAIGHT_STEP_M = 0.5
STRAIGHT_NOISE_M = 0.01
STRAIGHT_ROTATION_ERROR_DEG = 0.1
MAX_ALIGNED_ROTATION_DEG = 1.0


def rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def smooth_groundtruth(count: int, radius_m: float) -> np.ndarray:
    """(N, 4, 4) poses along a 3-D loop, heading along the tangent."""
    s = 0.004 * np.arange(count)
    pos = np.stack([radius_m * np.sin(s), 0.6 * radius_m * np.sin(2 * s), 0.05 * radius_m * np.sin(3 * s)], 1)
    tangent = np.gradient(pos, axis=0)
    poses = np.tile(np.eye(4), (count, 1, 1))
    for k in range(count):
        yaw = np.arctan2(tangent[k, 1], tangent[k, 0])
        pitch = -np.arctan2(tangent[k, 2], np.linalg.norm(tangent[k, :2]))
        cp, sp = np.cos(pitch), np.sin(pitch)
        poses[k, :3, :3] = rot_z(yaw) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
        poses[k, :3, 3] = pos[k]
    return poses


def drifting_estimate(gt: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Relative motions with a yaw and scale drift, then position noise, then a rigid offset."""
    est = [gt[0].copy()]
    for k in range(1, len(gt)):
        rel = np.linalg.inv(gt[k - 1]) @ gt[k]
        rel[:3, :3] = rel[:3, :3] @ rot_z(YAW_DRIFT_RAD_PER_FRAME)
        rel[:3, 3] *= SCALE_DRIFT
        est.append(est[-1] @ rel)
    est = np.array(est)
    est[:, :3, 3] += rng.normal(0.0, NOISE_SIGMA_M, (len(est), 3))
    offset = np.eye(4)
    offset[:3, :3] = rot_z(0.7)
    offset[:3, 3] = [5.0, -3.0, 1.0]
    return offset @ est


def quat_xyzw(r: np.ndarray) -> np.ndarray:
    """Rotation matrix -> unit quaternion (x, y, z, w), w >= 0."""
    w = 0.5 * np.sqrt(max(0.0, 1.0 + np.trace(r)))
    x = 0.5 * np.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) * np.sign(r[2, 1] - r[1, 2] or 1.0)
    y = 0.5 * np.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) * np.sign(r[0, 2] - r[2, 0] or 1.0)
    z = 0.5 * np.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) * np.sign(r[1, 0] - r[0, 1] or 1.0)
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


def write_tum(path: Path, stamps_s: np.ndarray, poses: np.ndarray) -> Path:
    with open(path, "w") as f:
        for t, p in zip(stamps_s, poses):
            q = quat_xyzw(p[:3, :3])
            f.write(
                f"{t:.9f} {p[0, 3]:.12f} {p[1, 3]:.12f} {p[2, 3]:.12f} "
                f"{q[0]:.15f} {q[1]:.15f} {q[2]:.15f} {q[3]:.15f}\n"
            )
    return path


def write_kitti(path: Path, poses: np.ndarray) -> Path:
    np.savetxt(path, poses[:, :3, :].reshape(-1, 12), fmt="%.15e")
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    rng = np.random.default_rng(7)
    gt = smooth_groundtruth(3000, radius_m=150.0)
    est = drifting_estimate(gt, rng)
    stamps = FIRST_STAMP_S + FRAME_PERIOD_S * np.arange(len(gt))
    d = tmp_path_factory.mktemp("traj")
    return {
        "gt": write_tum(d / "gt.tum", stamps, gt),
        "est": write_tum(d / "est.tum", stamps, est),
        "gt_kitti": write_kitti(d / "gt.kitti", gt),
        "est_kitti": write_kitti(d / "est.kitti", est),
        "gt_poses": gt,
        "est_poses": est,
        "dir": d,
    }


def evo_pair(files):
    from evo.core import sync
    from evo.tools import file_interface

    ref = file_interface.read_tum_trajectory_file(str(files["gt"]))
    est = file_interface.read_tum_trajectory_file(str(files["est"]))
    return sync.associate_trajectories(ref, est, max_diff=0.01)


def assert_ape_equals_evos(ours: dict, ref, est, abs_tol: float = 0.0) -> None:
    """eval.json's "ape" translation and rotation statistics equal evo's APE of the aligned est."""
    from evo.core import metrics

    for relation, key in (
        (metrics.PoseRelation.translation_part, "translation_m"),
        (metrics.PoseRelation.rotation_angle_deg, "rotation_deg"),
    ):
        ape = metrics.APE(relation)
        ape.process_data((ref, est))
        stats = ape.get_all_statistics()
        for name in ("rmse", "mean", "median", "max"):
            assert ours[key][name] == pytest.approx(stats[name], rel=REL_TOL, abs=abs_tol), (key, name)


def test_aligned_ape_matches_evo(files):
    pytest.importorskip("evo")
    ref, est = evo_pair(files)
    est.align(ref, correct_scale=False)
    ours = evaluation.evaluate_files(files["est"], files["gt"], plot=False)
    assert_ape_equals_evos(ours["ape"], ref, est)
    assert ours["associated_poses"] == ref.num_poses


def test_ape_aligned_at_the_origin_matches_evo(files, tmp_path):
    """`farlio eval --align-origin` against evo's `align_origin`: the drift from the first pose."""
    pytest.importorskip("evo")
    from farlio import cli

    ref, est = evo_pair(files)
    est.align_origin(ref)
    out = tmp_path / "origin"
    assert (
        cli.main(["eval", str(files["est"]), str(files["gt"]), "--out", str(out), "--align-origin", "--no-plot"]) == 0
    )
    ours = json.loads((out / "eval.json").read_text())["ape"]
    assert ours["alignment"]["method"] == "origin"
    assert_ape_equals_evos(ours, ref, est, abs_tol=1e-9)
    # the drift from the start exceeds the least-squares fit's error, which spreads it over the run
    fitted = evaluation.evaluate_files(files["est"], files["gt"], plot=False)["ape"]
    assert ours["translation_m"]["rmse"] > fitted["translation_m"]["rmse"]
    with pytest.raises(SystemExit):
        cli.main(["eval", str(files["est"]), str(files["gt"]), "--out", str(out), "--align-origin", "--align-scale"])


@pytest.mark.parametrize(
    "delta,unit,all_pairs", [(1, "frames", False), (10, "frames", True), (5.0, "m", False), (20.0, "m", True)]
)
def test_rpe_matches_evo(files, delta, unit, all_pairs):
    pytest.importorskip("evo")
    from evo.core import metrics

    ref, est = evo_pair(files)
    evo_unit = metrics.Unit.meters if unit == "m" else metrics.Unit.frames
    ours = evaluation.evaluate_files(
        files["est"], files["gt"], plot=False, rpe_delta=delta, rpe_unit=unit, rpe_all_pairs=all_pairs
    )
    for relation, key in (
        (metrics.PoseRelation.translation_part, "translation_m"),
        (metrics.PoseRelation.rotation_angle_deg, "rotation_deg"),
    ):
        rpe = metrics.RPE(relation, delta=delta, delta_unit=evo_unit, all_pairs=all_pairs, pairs_from_reference=True)
        rpe.process_data((ref, est))
        stats = rpe.get_all_statistics()
        assert ours["rpe"]["pair_count"] == len(rpe.error)
        for name in ("rmse", "mean", "median", "max"):
            assert ours["rpe"][key][name] == pytest.approx(stats[name], rel=REL_TOL), (key, name)


def brute_force_kitti(gt: np.ndarray, est: np.ndarray, lengths_m, step: int) -> tuple[float, float]:
    """Mean translational error [%] and rotational error [deg/100 m] over all segments."""
    dist = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(gt[:, :3, 3], axis=0), axis=1))])
    t_errs, r_errs = [], []
    for i in range(0, len(gt), step):
        for length in lengths_m:
            later = np.nonzero(dist >= dist[i] + length)[0]
            if len(later) == 0:
                continue
            j = later[0]
            e = np.linalg.inv(np.linalg.inv(gt[i]) @ gt[j]) @ (np.linalg.inv(est[i]) @ est[j])
            t_errs.append(np.linalg.norm(e[:3, 3]) / length)
            r_errs.append(np.arccos(np.clip(0.5 * (np.trace(e[:3, :3]) - 1.0), -1.0, 1.0)) / length)
    return 100.0 * np.mean(t_errs), np.degrees(np.mean(r_errs)) * 100.0


def test_kitti_rpe_matches_brute_force(files):
    gt, est = files["gt_poses"], files["est_poses"]
    ours = evaluation.evaluate_files(files["est"], files["gt"], plot=False, kitti_step=3)
    path_m = ours["groundtruth_path_length_m"]
    lengths = KITTI_LENGTHS_M if path_m >= 1000.0 else [length / 10 for length in KITTI_LENGTHS_M]
    assert ours["kitti_rpe"]["segment_lengths_m"] == lengths
    t_pct, r_deg = brute_force_kitti(gt, est, lengths, step=3)
    assert ours["kitti_rpe"]["translation_pct"] == pytest.approx(t_pct, rel=REL_TOL)
    assert ours["kitti_rpe"]["rotation_deg_per_100m"] == pytest.approx(r_deg, rel=REL_TOL)


def test_kitti_rpe_matches_kiss_icp(files):
    kiss_metrics = pytest.importorskip("kiss_icp.metrics")
    gt, est = files["gt_poses"], files["est_poses"]
    ours = evaluation.evaluate_files(
        files["est_kitti"],
        files["gt_kitti"],
        plot=False,
        kitti_step=KITTI_DEVKIT_STEP,
        segment_lengths_m=KITTI_LENGTHS_M,
    )
    assert ours["kitti_rpe"]["segment_count"] > 0
    kiss_t, kiss_r = kiss_metrics.sequence_error(gt, est)
    # kiss-icp reports the translational error in percent and the rotational one in deg/m. The
    # translation agrees to REL_TOL; kiss-icp's rotational figure differs from ours (and from the
    # brute force above, which ours matches to REL_TOL) by about 5e-4 relative on this data, for a
    # reason not established (its single-precision output is suspected), hence the looser bound.
    assert ours["kitti_rpe"]["translation_pct"] == pytest.approx(kiss_t, rel=REL_TOL)
    assert ours["kitti_rpe"]["rotation_deg_per_100m"] / 100.0 == pytest.approx(kiss_r, rel=KISS_ROTATION_REL_TOL)


def test_tum_and_kitti_files_give_the_same_result(files):
    tum = evaluation.evaluate_files(files["est"], files["gt"], plot=False)
    kitti = evaluation.evaluate_files(files["est_kitti"], files["gt_kitti"], plot=False)
    assert kitti["ape"]["translation_m"]["rmse"] == pytest.approx(tum["ape"]["translation_m"]["rmse"], rel=1e-6)
    assert kitti["kitti_rpe"]["translation_pct"] == pytest.approx(tum["kitti_rpe"]["translation_pct"], rel=1e-6)


def test_identical_files_give_zero_and_full_coverage(files):
    r = evaluation.evaluate_files(files["gt"], files["gt"], plot=False)
    assert r["coverage"] == 1.0
    assert r["ape"]["translation_m"]["max"] < 1e-9
    assert r["ape"]["translation_raw_m"]["max"] == 0.0
    assert r["kitti_rpe"]["translation_pct"] < 1e-9
    assert r["rpe"]["translation_m"]["max"] < 1e-9


def test_cli_writes_json_and_plot(files, tmp_path):
    from farlio import cli

    out = tmp_path / "out"
    assert cli.main(["eval", str(files["est"]), str(files["gt"]), "--out", str(out)]) == 0
    summary = json.loads((out / "eval.json").read_text())
    assert summary["associated_poses"] == len(files["gt_poses"])
    assert (out / "eval.png").stat().st_size > 0


def test_curved_run_is_aligned_by_umeyama(files):
    ours = evaluation.evaluate_files(files["est"], files["gt"], plot=False)
    assert ours["ape"]["alignment"]["method"] == "umeyama"


def so3_exp(phi: np.ndarray) -> np.ndarray:
    angle = np.linalg.norm(phi)
    k = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]]) / angle
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_straight_run_takes_the_rotation_about_the_line_from_the_orientations(tmp_path, capsys, seed):
    """Positions on a line leave the rotation about it free (Umeyama's pick is arbitrary, up to
    180 degrees off); eval.json names the alignment, and the aligned rotation error is the true one."""
    from farlio import cli

    rng = np.random.default_rng(seed)
    gt = np.tile(np.eye(4), (STRAIGHT_POSES, 1, 1))
    gt[:, 0, 3] = STRAIGHT_STEP_M * np.arange(STRAIGHT_POSES)
    est = gt.copy()
    sigma_rad = np.radians(STRAIGHT_ROTATION_ERROR_DEG) / np.sqrt(3.0)
    true_sq = []
    for p in est:
        phi = rng.normal(0.0, sigma_rad, 3)
        true_sq.append(np.dot(phi, phi))
        p[:3, :3] = p[:3, :3] @ so3_exp(phi)
    est[:, :3, 3] += rng.normal(0.0, STRAIGHT_NOISE_M, (STRAIGHT_POSES, 3))
    offset = np.eye(4)
    offset[:3, :3] = so3_exp(np.array([0.3, -1.1, 2.0]))
    offset[:3, 3] = [4.0, -2.0, 7.0]
    est = offset @ est
    stamps = FIRST_STAMP_S + FRAME_PERIOD_S * np.arange(STRAIGHT_POSES)
    out = tmp_path / "out"
    gt_file, est_file = write_tum(tmp_path / "gt.tum", stamps, gt), write_tum(tmp_path / "est.tum", stamps, est)
    assert cli.main(["eval", str(est_file), str(gt_file), "--out", str(out), "--no-plot"]) == 0
    assert "APE aligned (umeyama_orientation)" in capsys.readouterr().out
    ape = json.loads((out / "eval.json").read_text())["ape"]
    assert ape["alignment"]["method"] == "umeyama_orientation"
    assert ape["alignment"]["rank_deficient"]
    true_rmse_deg = np.degrees(np.sqrt(np.mean(true_sq)))
    assert ape["rotation_deg"]["rmse"] < MAX_ALIGNED_ROTATION_DEG
    assert ape["rotation_deg"]["rmse"] == pytest.approx(true_rmse_deg, abs=0.05)
