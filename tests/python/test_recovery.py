"""Recovery from faults: scans that carry nothing (2 s of
empty scans at speed), a bogus scan, and corrupt IMU samples. The run must go on, write no NaN and
no wild jump, report what happened (timing.csv drop_reason, summary.json), and stay close to the
accuracy of the clean run on the same sequence."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from farlio import _core
from farlio.config import load_config
from farlio.datasets import open_dataset
from farlio.runner import replay_options, run_dataset
from farlio.simulation import generate

PROFILE, DURATION_S, SEED = "urban", 10.0, 2
OUTAGE_S = (4.0, 6.0)  # seconds after the first scan: the scans in between are empty
# Poses are the registration's (cm level) except across the outage, where the IMU alone carries
# them for 2 s; the bound allows the dead reckoning of a consumer-grade IMU over that time.
OUTAGE_APE_BOUND_M = 0.25
# A pose may not move further between consecutive scans than the vehicle can (urban: <= 15 m/s,
# 1.5 m a scan) plus the correction when the registration returns: LiDAR-only extrapolates its last
# velocity through the 2 s outage and corrects ~2 m at its end.
MAX_STEP_M = {True: 3.0, False: 6.0}


def _scan_files(seq: Path) -> list[Path]:
    return sorted((seq / "lidar").glob("*.pcd"), key=lambda p: int(p.stem))


def _run(seq: Path, out: Path, fused: bool = True) -> dict:
    config = load_config(None, [] if fused else ["fusion.enabled=false"])
    return run_dataset(
        open_dataset(seq), out, config, progress=False, plot=False, options=replay_options("fixed", 0.02)
    )


def _check_poses(out: Path, fused: bool = True) -> None:
    """Every pose written is finite and no consecutive scan poses are further apart than possible."""
    for name in ("scans_body.tum", "odometry_body.tum"):
        path = out / name
        if not path.exists():
            continue
        rows = np.loadtxt(path, comments="#", ndmin=2)
        assert np.isfinite(rows).all(), name
        if name == "scans_body.tum":
            steps = np.linalg.norm(np.diff(rows[:, 1:4], axis=0), axis=1)
            assert steps.max() < MAX_STEP_M[fused], (name, steps.max())


def _drop_reasons(out: Path) -> list[str]:
    with open(out / "timing.csv") as f:
        return [row["drop_reason"] for row in csv.DictReader(f)]


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    root = tmp_path_factory.mktemp("recovery")
    seq = root / "seq"
    generate(PROFILE, seq, duration_s=DURATION_S, seed=SEED)
    return seq, _run(seq, root / "clean")


def _copy_sequence(seq: Path, dst: Path) -> Path:
    import shutil

    shutil.copytree(seq, dst)
    return dst


@pytest.mark.parametrize("fused", [True, False], ids=["lio", "lidar_only"])
def test_two_seconds_of_empty_scans_at_speed(tmp_path, clean, fused):
    seq, clean_summary = clean
    bad = _copy_sequence(seq, tmp_path / "seq")
    files = _scan_files(bad)
    t0 = int(files[0].stem)
    emptied = 0
    for f in files:
        t = (int(f.stem) - t0) / _core.NS_PER_S
        if OUTAGE_S[0] <= t < OUTAGE_S[1]:
            _core.io.write_pcd(f, _core.Scan(np.zeros((0, 3), dtype=np.float32)), "binary")
            emptied += 1
    assert emptied >= 15
    out = tmp_path / "out"
    s = _run(bad, out, fused)
    _check_poses(out, fused)
    reasons = _drop_reasons(out)
    assert sum("nothing to register against" in r for r in reasons) >= emptied - 1
    assert s["registration_failed"] >= emptied - 1
    if fused:  # the IMU carries the pose across the outage; LiDAR-only extrapolates its velocity
        assert s["accuracy"]["ape"]["translation_m"]["rmse"] < OUTAGE_APE_BOUND_M, s["accuracy"]["ape"]
    # after the outage the registration is back: the last second is registered
    assert all(r == "" for r in reasons[-10:]), reasons[-10:]


def test_a_bogus_scan_is_not_trusted(tmp_path, clean):
    """One scan replaced by random points in the sensor's range: the run's accuracy must not
    suffer (the scan fails, or the fusion's gate rejects it)."""
    seq, clean_summary = clean
    bad = _copy_sequence(seq, tmp_path / "seq")
    files = _scan_files(bad)
    rng = np.random.default_rng(7)
    points = rng.uniform([-40.0, -40.0, -2.0], [40.0, 40.0, 10.0], size=(20000, 3)).astype(np.float32)
    _core.io.write_pcd(files[len(files) // 2], _core.Scan(points), "binary")
    out = tmp_path / "out"
    s = _run(bad, out)
    _check_poses(out)
    ape, clean_ape = (x["accuracy"]["ape"]["translation_m"]["rmse"] for x in (s, clean_summary))
    assert ape <= 1.5 * clean_ape + 0.005, (ape, clean_ape)


def test_corrupt_imu_samples_are_rejected(tmp_path, clean):
    """A bit flip (1e30 m/s^2), a 1e4 m/s^2 spike and a 30 rad/s gyro glitch in imu.csv: rejected
    and reported, accuracy as without them. (A NaN in imu.csv is dropped by the reader with a
    warning naming the line, test_io_sequence.cpp; the gate's NaN case is test_imu_gate.cpp.)"""
    seq, clean_summary = clean
    bad = _copy_sequence(seq, tmp_path / "seq")
    lines = (bad / "imu.csv").read_text().splitlines()
    n = len(lines) - 1
    corrupt = {n // 5: (0, 0, 0, 1e30, 0, 9.81), n // 3: (0, 0, 0, 1e4, 0, 9.81), n // 2: (30.0, 0, 0, 0, 0, 9.81)}
    for i, values in corrupt.items():
        stamp = lines[i].split(",")[0]
        lines[i] = ",".join([stamp, *(repr(float(v)) for v in values)])
    (bad / "imu.csv").write_text("\n".join(lines) + "\n")
    out = tmp_path / "out"
    s = _run(bad, out)
    _check_poses(out)
    assert s["fusion"]["imu_samples_rejected"] == len(corrupt)
    ape, clean_ape = (x["accuracy"]["ape"]["translation_m"]["rmse"] for x in (s, clean_summary))
    rpe, clean_rpe = (x["accuracy"]["kitti_rpe"]["translation_pct"] for x in (s, clean_summary))
    assert ape <= 1.05 * clean_ape + 1e-4, (ape, clean_ape)
    assert rpe <= 1.05 * clean_rpe + 1e-3, (rpe, clean_rpe)
