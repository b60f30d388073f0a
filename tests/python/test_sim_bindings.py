"""The sequence generator through the Python bindings: configuration, scans as numpy views,
IMU arrays, exact states, determinism and GIL release."""

from __future__ import annotations

import threading

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")
sim = core.sim

SHORT_DURATION_S = 1.0


def short_config(name: str, noise_free: bool = False):
    cfg = sim.default_config(name)
    cfg.duration_s = SHORT_DURATION_S
    cfg.noise_free = noise_free
    return cfg


def test_profiles_and_defaults():
    assert sim.parse_profile("urban") == sim.Profile.Urban
    with pytest.raises(ValueError, match="racetrack"):
        sim.parse_profile("moon")
    cfg = sim.default_config(sim.Profile.Racetrack)
    assert cfg.lidar_rate_hz == 20.0 and cfg.imu_rate_hz == 800.0
    assert cfg.noise.accel_noise_std_m_s2 > sim.default_config("urban").noise.accel_noise_std_m_s2


def test_scan_points_times_and_truth():
    gen = sim.SequenceGenerator(short_config("handheld", noise_free=True))
    assert gen.num_scans() == 10
    scan = gen.scan(3)
    pts = np.asarray(scan.points)
    assert pts.shape[1] == 3 and 50_000 < pts.shape[0] <= 57_600
    t = np.asarray(scan.time_s)
    assert t.min() >= 0.0 and t.max() < 0.1
    assert scan.end_stamp_ns - scan.start_stamp_ns == gen.scan_period_ns()
    gt = gen.groundtruth_scans()
    assert len(gt) == gen.num_scans()
    stamp_ns, pose = gt[3]
    assert stamp_ns == scan.end_stamp_ns
    state = gen.state(scan.end_stamp_ns)
    np.testing.assert_allclose(pose.translation, state.pose_world_body.translation, atol=1e-12)


def test_imu_arrays_match_samples_and_gravity():
    gen = sim.SequenceGenerator(short_config("urban", noise_free=True))
    stamps, gyro, accel = gen.imu_arrays()
    samples = gen.imu()
    assert stamps.shape == (len(samples),) and gyro.shape == (len(samples), 3)
    assert np.all(np.diff(stamps) > 0)
    np.testing.assert_allclose(accel[0], samples[0].accel_m_s2)
    # Urban starts standing still and level: the accelerometer reads +g along body z.
    assert accel[0, 2] == pytest.approx(gen.gravity_m_s2(), abs=0.2)


def test_determinism_and_threads():
    cfg = short_config("urban")
    gen = sim.SequenceGenerator(cfg)
    results = {}

    def work(i):
        results[i] = np.asarray(gen.scan(i).points).copy()

    threads = [threading.Thread(target=work, args=(i,)) for i in (2, 5)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    np.testing.assert_array_equal(results[5], np.asarray(sim.SequenceGenerator(cfg).scan(5).points))
    cfg.seed = 99
    assert not np.array_equal(results[5], np.asarray(sim.SequenceGenerator(cfg).scan(5).points))
    desc = gen.description()
    assert desc["profile"] == "urban" and desc["seed"] == "1"


def test_tunnel_meta_has_the_featureless_section(tmp_path):
    # meta.yaml of a generated tunnel sequence carries the featureless section's bounds, as numbers,
    # consistent with the exact motion (evaluation scripts read them).
    import yaml
    from farlio.simulation import generate

    generate("tunnel", tmp_path, duration_s=0.2)
    meta = yaml.safe_load((tmp_path / "meta.yaml").read_text())
    assert meta["profile"] == "tunnel"
    x0, x1 = float(meta["featureless_start_x_m"]), float(meta["featureless_end_x_m"])
    t0, t1 = float(meta["featureless_start_s"]), float(meta["featureless_end_s"])
    assert x1 - x0 >= 500.0 and 0.0 < t0 < t1 < sim.default_config("tunnel").duration_s
    gen = sim.SequenceGenerator(sim.default_config("tunnel"))
    start = int(meta["start_stamp_ns"])
    for t, x in ((t0, x0), (t1, x1)):
        pose = gen.state(start + round(t * core.NS_PER_S)).pose_world_body
        assert pose.translation[0] == pytest.approx(x, abs=1e-3)


def test_imu_grades_through_make_config():
    from farlio.simulation import IMU_GRADES, make_config

    assert IMU_GRADES[0] == "profile"
    default = sim.default_config("urban")
    cfg = make_config("urban", imu_grade="profile")
    assert cfg.noise.gyro_noise_std_rad_s == default.noise.gyro_noise_std_rad_s and not cfg.imu_errors.any()
    # Consumer class: 0.01 deg/s/sqrt(Hz) at the urban 100 Hz, a turn-on draw, the car's vibration.
    cfg = make_config("urban", duration_s=SHORT_DURATION_S, imu_grade="consumer", seed=4)
    assert cfg.noise.gyro_noise_std_rad_s == pytest.approx(np.radians(0.01) * 10.0)
    assert cfg.imu_errors.vibration.any() and cfg.imu_errors.gyro_scale_factor_std_ppm == 5000.0
    draw = sim.draw_imu_errors(cfg.imu_errors, 4)
    assert np.asarray(draw.gyro_response).shape == (3, 3)
    desc = sim.SequenceGenerator(cfg).description()
    assert (
        "gyro_turn_on_bias_rad_s" in desc
        and "gyro_turn_on_bias_rad_s" not in sim.SequenceGenerator(short_config("urban")).description()
    )
    assert not make_config("urban", imu_grade="tactical", vibration=False).imu_errors.vibration.any()
    with pytest.raises(ValueError, match="tactical"):
        make_config("urban", imu_grade="navigation")


def test_ideal_grade_is_the_exact_imu_with_lidar_noise():
    from farlio.simulation import make_config

    ideal = make_config("handheld", duration_s=SHORT_DURATION_S, imu_grade="ideal")
    assert ideal.noise.range_noise_std_m > 0.0
    _, gyro, accel = sim.SequenceGenerator(ideal).imu_arrays()
    _, gyro_exact, accel_exact = sim.SequenceGenerator(short_config("handheld", noise_free=True)).imu_arrays()
    np.testing.assert_array_equal(gyro, gyro_exact)
    np.testing.assert_array_equal(accel, accel_exact)


def test_simulate_cli_imu_grade_writes_the_error_model(tmp_path):
    import yaml
    from farlio.cli import main

    out = tmp_path / "seq"
    args = ["simulate", "handheld", "--out", str(out), "--duration", "0.25", "--no-progress"]
    assert main([*args, "--imu-grade", "industrial", "--seed", "2"]) == 0
    meta = yaml.safe_load((out / "meta.yaml").read_text())
    assert float(meta["accel_scale_factor_std_ppm"]) == 1000.0 and int(meta["seed"]) == 2
    imu = np.loadtxt(out / "imu.csv", delimiter=",", skiprows=1, ndmin=2)
    assert imu.shape[0] == 51  # 0.25 s at 200 Hz, both ends


def test_an_imu_offset_puts_the_samples_between_the_periods():
    """imu_time_offset_s (farlio simulate --imu-offset): a 100 Hz IMU 5 ms off the sequence clock."""
    from farlio.simulation import make_config

    cfg = make_config("urban", duration_s=SHORT_DURATION_S, imu_time_offset_s=0.005)
    gen = sim.SequenceGenerator(cfg)
    stamps = np.array([s.stamp_ns for s in gen.imu()]) - cfg.start_stamp_ns
    assert np.all(stamps % 10_000_000 == 5_000_000) and len(stamps) == 100
    assert gen.description()["imu_time_offset_s"] == "0.005"
    cfg.imu_time_offset_s = 0.01
    with pytest.raises(ValueError, match="imu_time_offset_s"):
        sim.SequenceGenerator(cfg)
