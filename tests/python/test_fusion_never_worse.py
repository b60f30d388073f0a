"""The fusion must never make the odometry worse: on generated sequences of every
profile and on seeds other than the one the other tests use, the LIO's scan poses are at least as
accurate as LiDAR-only on the same data, in APE, rotation RMSE and KITTI-style RPE (fixed 20 ms
latency). Measured with figures/fusion_accuracy.py; docs/fusion.md, "IMU biases, the registration's
covariance, the kernel with the fusion's guess"."""

from __future__ import annotations

import pytest
from farlio.config import load_config
from farlio.datasets import open_dataset
from farlio.runner import replay_options, run_dataset
from farlio.simulation import generate

# profile, duration (s): long enough for 100 m RPE segments (racetrack: the standing start)
PROFILES = [("urban", 10.0), ("handheld", 25.0), ("racetrack", 6.0)]
SEEDS = [2, 3]
# The replay is deterministic; the margin only keeps the test from failing on a change of the last
# digit where both modes are equally good (urban rotation).
MARGIN = 1.05
# Known open (docs/fusion.md): where both rotation errors are at the registration's own level (urban
# ~0.02 deg, the racetrack launch ~0.03 deg) the LIO's can be up to 0.006 deg larger; on the 30 s
# racetrack and on handheld it is clearly smaller.
ROTATION_SLACK_DEG = 0.01
# The 30 s racetrack (1.4 km, 0 -> 250 km/h) on the two seeds where the LIO was worse than
# LiDAR-only before the kernel cap (registration.fused_kernel_scale_m; docs/fusion.md):
# strictly no worse, no margin.
RACETRACK_30S_SEEDS = [3, 4]


def _accuracy(seq, out, fused: bool) -> dict[str, float]:
    config = load_config(None, [] if fused else ["fusion.enabled=false"])
    s = run_dataset(open_dataset(seq), out, config, progress=False, plot=False, options=replay_options("fixed", 0.02))
    a = s["accuracy"]
    return {
        "ape_m": a["ape"]["translation_m"]["rmse"],
        "rotation_deg": a["ape"]["rotation_deg"]["rmse"],
        "rpe_pct": a["kitti_rpe"]["translation_pct"],
    }


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("profile,duration", PROFILES)
def test_lio_is_never_worse_than_lidar_only(tmp_path, profile, duration, seed):
    seq = tmp_path / "seq"
    generate(profile, seq, duration_s=duration, seed=seed)
    lio = _accuracy(seq, tmp_path / "lio", True)
    lidar = _accuracy(seq, tmp_path / "lidar", False)
    print(profile, seed, "LIO", lio, "LiDAR-only", lidar)
    assert lidar["rpe_pct"] > 0.0  # long enough for KITTI segments
    for metric in lio:
        slack = ROTATION_SLACK_DEG if metric == "rotation_deg" else 0.0
        assert lio[metric] <= MARGIN * lidar[metric] + slack, (metric, lio, lidar)


@pytest.mark.parametrize("seed", RACETRACK_30S_SEEDS)
def test_lio_is_never_worse_than_lidar_only_at_racing_speed(tmp_path, seed):
    seq = tmp_path / "seq"
    generate("racetrack", seq, duration_s=30.0, seed=seed)
    lio = _accuracy(seq, tmp_path / "lio", True)
    lidar = _accuracy(seq, tmp_path / "lidar", False)
    print("racetrack 30 s", seed, "LIO", lio, "LiDAR-only", lidar)
    for metric in lio:
        assert lio[metric] <= lidar[metric], (metric, lio, lidar)


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_a_forward_livox_on_the_racetrack_starts_the_filter_standing(seed):
    """A forward-looking Livox Avia model on the racetrack (20 s from a standstill): nearly every scan
    is degenerate along the track. Standing, its scans hold still within their own stds, a few
    constrain every direction, and the IMU reads gravity alone (its noise measured: 1.3 s), so the filter
    starts at rest from them and gives the 100 Hz output: scan RPE 0.077-0.088 % against
    LiDAR-only's 0.159-0.165 %. The APE is 0.057-0.090 m against 0.063-0.077 m, up to 1.4x on two
    seeds (docs/fusion.md, "Degeneracy"). The gyro's unit is judged on scans that constrain every
    direction only: the rotations of the degenerate ones once added up to a turn the gyro did not
    follow, and a "dead gyro" verdict ended the fusion (seeds 3-4)."""
    from farlio.simulation import Recording, make_config, replay, stretch_accuracy

    rec = Recording(make_config("racetrack", seed=seed, duration_s=20.0, lidar="avia"))
    lio, lidar_only = stretch_accuracy(replay(rec, [])), stretch_accuracy(replay(rec, ["fusion.enabled=false"]))
    print(f"racetrack Avia seed {seed}: LIO {lio}, LiDAR-only {lidar_only}")
    assert lio["initialization"].mode == "standstill", lio
    assert lio["first_output_s"] < 1.5, lio  # once the IMU's noise is measured (1000 samples at 800 Hz)
    assert lio["rpe_pct"] <= 0.7 * lidar_only["rpe_pct"], (lio, lidar_only)
    assert lio["ape_m"] <= 1.5 * lidar_only["ape_m"], (lio, lidar_only)
    assert lio["odom_ape_m"] <= 1.5 * lidar_only["ape_m"], (lio, lidar_only)
    assert lio["failed"] == lio["map_restarts"] == 0, lio
    assert lio.get("reinit") == 0, f"the fusion ended or re-initialised: {lio}"


@pytest.mark.parametrize("seed", [1, 3])
def test_a_mid360_on_the_racetrack_starts_the_filter_standing_and_beats_lidar_only(seed):
    """A Livox Mid-360 model on the racetrack (20 s from a standstill): its scans are degenerate along
    the track from the start. Started at rest from them (above), the LIO is better than LiDAR-only
    in APE and RPE (0.42-0.43 m against 0.50-0.57 m, 0.15-0.17 % against 0.27 %); held until a scan
    constrained every direction, the filter never started on these seeds and the run slid as
    LiDAR-only slides (0.64-0.67 m)."""
    from farlio.simulation import Recording, make_config, replay, stretch_accuracy

    rec = Recording(make_config("racetrack", seed=seed, duration_s=20.0, lidar="mid360"))
    lio, lidar_only = stretch_accuracy(replay(rec, [])), stretch_accuracy(replay(rec, ["fusion.enabled=false"]))
    print(f"racetrack Mid-360 seed {seed}: LIO {lio}, LiDAR-only {lidar_only}")
    assert lio["initialization"].mode == "standstill", lio
    assert lio["ape_m"] <= lidar_only["ape_m"] and lio["rpe_pct"] <= lidar_only["rpe_pct"], (lio, lidar_only)
    assert lio["failed"] == lio["map_restarts"] == 0 and lio.get("reinit") == 0, lio


def test_a_forward_livox_with_a_race_cars_imu_does_not_start_the_filter_standing():
    """The same Avia with a vibrating race car's IMU (noisier than the filter's configured input
    noise): a filter started from degenerate scans carries the unconstrained direction on that
    accelerometer, and ran 0.18-0.40 m off against LiDAR-only's 0.063-0.075 m. The standing start
    from degenerate scans is therefore refused; the IMU serves the scans' guess and undistortion
    and the scan poses stay no worse than LiDAR-only's."""
    import math

    from farlio.simulation import Recording, make_config, replay, stretch_accuracy

    rate = make_config("racetrack").imu_rate_hz
    noisy = {"gyro_noise_std_rad_s": 3e-3 * math.sqrt(rate), "accel_noise_std_m_s2": 7e-2 * math.sqrt(rate)}
    rec = Recording(make_config("racetrack", seed=2, duration_s=20.0, lidar="avia", **noisy))
    lio, lidar_only = stretch_accuracy(replay(rec, [])), stretch_accuracy(replay(rec, ["fusion.enabled=false"]))
    print(f"racetrack Avia, race car's IMU: LIO {lio}, LiDAR-only {lidar_only}")
    assert lio["initialization"].mode != "standstill", lio
    assert lio["ape_m"] <= lidar_only["ape_m"], (lio, lidar_only)


@pytest.mark.parametrize("lidar,seed", [("hdl32", 1), ("hdl32", 2), ("vlp16", 1)])
def test_a_sparse_spinning_lidar_on_the_racetrack_is_no_worse_than_lidar_only(lidar, seed):
    """A 32- or 16-beam spinning LiDAR at 10 Hz on the racetrack (30 s from a standstill, up to 70
    m/s): most scans are degenerate along the track. The registration holds that direction at the
    fusion's prior and the fusion gets the scan's own step along it at its covariance: HDL-32 APE
    0.43 / 0.40 m, VLP-16 1.52 m, no re-initialisation. With the direction from the IMU alone the
    along-track error grew with the racing IMU's drift (HDL-32 1.17 / 1.69 m against LiDAR-only's
    0.64 / 0.60 m, VLP-16 27.5 m against 7.25 m; docs/fusion.md, "Degeneracy")."""
    from farlio.simulation import Recording, make_config, replay, stretch_accuracy

    rec = Recording(make_config("racetrack", seed=seed, duration_s=30.0, lidar=lidar, lidar_rate_hz=10.0))
    lio, lidar_only = stretch_accuracy(replay(rec, [])), stretch_accuracy(replay(rec, ["fusion.enabled=false"]))
    print(f"racetrack {lidar} seed {seed}: LIO {lio}, LiDAR-only {lidar_only}")
    for metric in ("ape_m", "rpe_pct", "rot_deg"):
        assert lio[metric] <= lidar_only[metric], (metric, lio, lidar_only)
    assert lio["failed"] == lio["map_restarts"] == 0, lio
    assert lio.get("reinit") == 0, lio


@pytest.mark.parametrize("seed", [1, 3])
def test_a_forward_livox_carried_through_rooms_keeps_registering(seed):
    """A forward-looking Livox Avia model carried through rooms and a bare corridor (handheld, 30 s):
    facing close walls its scans fill few voxels. At the range rule's 1.33 m voxel they shrank to
    70-150 source points, registrations failed and both modes were lost (LIO 1.2-4.4 m with 6-8
    re-initialisations, LiDAR-only 3.4-90 m); the first scan now fills at least map.auto_min_voxels
    voxels (0.87 m here): LIO 0.017-0.021 m without a failure, LiDAR-only 1.5-2.0 m (the narrow view
    turning faster than its constant-velocity guess follows; docs/odometry.md, "Scale")."""
    from farlio.simulation import Recording, make_config, replay, stretch_accuracy

    rec = Recording(make_config("handheld", seed=seed, duration_s=30.0, lidar="avia"))
    lio, lidar_only = stretch_accuracy(replay(rec, [])), stretch_accuracy(replay(rec, ["fusion.enabled=false"]))
    print(f"handheld Avia seed {seed}: LIO {lio}, LiDAR-only {lidar_only}")
    assert lio["ape_m"] <= 0.05 and lio["rot_deg"] <= 1.0, lio
    for metric in ("ape_m", "rpe_pct", "rot_deg"):
        assert lio[metric] <= lidar_only[metric], (metric, lio, lidar_only)
    assert lio["failed"] == lio["map_restarts"] == lio["reinit"] == 0, lio
    assert lidar_only["failed"] == lidar_only["map_restarts"] == 0, lidar_only
    assert lidar_only["ape_m"] <= 3.0, lidar_only  # jumps, but is not lost


@pytest.mark.parametrize("lidar", ["avia", "mid360", "os128"])
def test_every_lidar_model_on_urban_is_no_worse_than_lidar_only(lidar):
    """Urban, 20 s from rest, seed 1, with a forward Livox Avia, a Livox Mid-360 and a 128-beam head,
    the same defaults: the LIO's APE, RPE and rotation error from the first pose are below
    LiDAR-only's, with no failure, re-initialisation or rejected LiDAR result (docs/fusion.md, "Every
    profile with every LiDAR model": Avia 0.021 against 0.032 deg, Mid-360 0.015 against 0.023,
    OS-128 0.014 against 0.016). The rotation after the APE's alignment of the positions is not
    asserted: on a nearly straight drive it keeps the roll with which the IMU levelled the LIO's map
    frame (the accelerometer's bias), which LiDAR-only's first-body frame does not have."""
    from farlio.simulation import Recording, make_config, replay, stretch_accuracy

    rec = Recording(make_config("urban", seed=1, duration_s=20.0, lidar=lidar))
    lio, lidar_only = stretch_accuracy(replay(rec, [])), stretch_accuracy(replay(rec, ["fusion.enabled=false"]))
    print(f"urban {lidar} seed 1: LIO {lio}, LiDAR-only {lidar_only}")
    for metric in ("ape_m", "rpe_pct", "rot_origin_deg"):
        assert lio[metric] <= lidar_only[metric], (metric, lio, lidar_only)
    assert lio["failed"] == lio["map_restarts"] == lio["reinit"] == lio["rejected"] == 0, lio
