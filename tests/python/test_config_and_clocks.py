"""Bad configurations, clocks and command lines (docs/hardening.md, "Configuration and clocks"): every
one ends in one line naming the option, field, file or line and a non-zero exit, never a traceback,
a hang or a run that writes garbage; an interrupted run keeps its summary and KITTI poses."""

from __future__ import annotations

import json
import math
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

core = pytest.importorskip("farlio._core")

from farlio.cli import main  # noqa: E402
from farlio.config import load_config  # noqa: E402
from farlio.simulation import generate  # noqa: E402

NS_PER_US = 1000
#: the IMU's clock this far ahead of the LiDAR's in the offset test (s)
IMU_OFFSET_S = 2
#: how long the interrupt test waits for frames before and for the exit after the signal (s)
RUN_START_TIMEOUT_S = 120
EXIT_TIMEOUT_S = 60
#: an accelerometer at rest, z up (m/s^2)
GRAVITY_UP = np.array([0.0, 0.0, 9.81])


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    path = tmp_path_factory.mktemp("seq") / "urban"
    generate("urban", path, duration_s=3.0)
    return path


def copy_of(sequence: Path, tmp_path: Path) -> Path:
    out = tmp_path / "copy"
    shutil.copytree(sequence, out)
    return out


def rewrite_imu_stamps(seq: Path, change) -> None:
    lines = (seq / "imu.csv").read_text().splitlines()
    rows = [lines[0]]
    for line in lines[1:]:
        stamp, rest = line.split(",", 1)
        rows.append(f"{change(int(stamp))},{rest}")
    (seq / "imu.csv").write_text("\n".join(rows) + "\n")


def one_line_error(capsys, *fragments: str) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    errors = [line for line in err.splitlines() if "error:" in line]
    assert len(errors) == 1, err
    for f in fragments:
        assert f in errors[0], errors[0]
    return errors[0]


# ---- config values --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name,value,message",
    [
        ("fusion.step_s", "0", "in [1e-04, 1], got 0"),
        ("fusion.history_s", "1e12", "in (0, 60], got 1e+12"),
        ("fusion.imu_gate.gap_limit_s", "1e15", "in (0, 60], got 1e+15"),
        ("map.voxel_size_m", "nan", "in [0.01, 100], got nan"),
        ("registration.max_iterations", "0", "in [1, 1e+06], got 0"),
        ("registration.convergence_norm", "nan", "in (0, 1000], got nan"),
        ("threshold.max_threshold_m", "0", "in (0, 1000], got 0"),
        ("registration.time_budget_factor", "0", "in (0, 1e+06] or inf, got 0"),
        ("preprocess.max_range_m", "0", "in (0, 10000] or inf, got 0"),
        ("fusion.imu_gate.max_bridged_gap_s", "-1", "in (0, 60], got -1"),
    ],
)
def test_a_bad_value_names_the_field_its_value_and_range(name, value, message):
    with pytest.raises(ValueError) as e:
        load_config(overrides=[f"{name}={value}"])
    assert f"'{name}' must be {message}" in str(e.value)


def test_every_numeric_field_has_a_finite_range():
    for name, _default, _doc, allowed in core.Config.fields():
        if isinstance(core.Config().get(name), bool) or name == "device":
            continue
        assert allowed.startswith("in "), f"{name}: {allowed}"


def test_a_rule_between_fields_gives_both_values():
    with pytest.raises(
        ValueError, match=r"fusion.imu_gate.gap_limit_s \(2\) must not exceed fusion.imu_gate.max_bridged_gap_s \(1\)"
    ):
        load_config(overrides=["fusion.imu_gate.gap_limit_s=2"])


def test_invalid_yaml_names_the_file_and_line(sequence, tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("map:\n  voxel_size_m: [1,\n")
    assert main(["run", str(sequence), "--out", str(tmp_path / "out"), "--config", str(bad)]) == 2
    one_line_error(capsys, f"{bad}:3: not valid YAML")


@pytest.mark.parametrize(
    "gravity,fragment",
    [
        ("-9.81", "(no sign: the direction comes from the accelerometer)"),
        ("1.0", "about 9.8 (in [9.5, 10.2]), got 1"),
        ("[0, 0, -9.81]", "expected the magnitude of gravity in m/s^2 (one number, about 9.8), got a list"),
    ],
)
def test_gravity_must_be_a_magnitude(sequence, tmp_path, capsys, gravity, fragment):
    seq = copy_of(sequence, tmp_path)
    calib = seq / "calib.yaml"
    calib.write_text(
        "\n".join(f"gravity: {gravity}" if x.startswith("gravity:") else x for x in calib.read_text().splitlines())
    )
    assert main(["run", str(seq), "--out", str(tmp_path / "out"), "--no-plot", "--no-progress"]) == 2
    one_line_error(capsys, "calib.yaml: key 'gravity'", fragment)


def test_gravity_is_checked_from_python():
    with pytest.raises(ValueError, match="gravity_m_s2: must be the magnitude of gravity"):
        core.OnlineOdometry(core.Config(), core.SE3(), -9.81)


# ---- command-line options ---------------------------------------------------------------------


@pytest.mark.parametrize(
    "args,fragment",
    [
        (
            ["eval", "a.tum", "b.tum", "--out", "o", "--max-time-diff", "-1"],
            "argument --max-time-diff: must be a number >= 0, got -1",
        ),
        (
            ["eval", "a.tum", "b.tum", "--out", "o", "--kitti-step", "0"],
            "argument --kitti-step: must be an integer >= 1, got 0",
        ),
        (
            ["eval", "a.tum", "b.tum", "--out", "o", "--segments", "-5"],
            "argument --segments: must be a number > 0, got -5",
        ),
        (["run", "seq", "--out", "o", "--max-frames", "-1"], "argument --max-frames: must be an integer >= 1, got -1"),
        (["run", "seq", "--out", "o", "--added-delay", "-5"], "argument --added-delay: must be a number >= 0, got -5"),
        (["run", "seq", "--out", "o", "--fixed-latency", "nan"], "argument --fixed-latency: must be a finite number"),
        (
            ["simulate", "urban", "--out", "o", "--dropout", "2"],
            "argument --dropout: must be a number in [0, 1], got 2",
        ),
        (["simulate", "urban", "--out", "o", "--seed", "-1"], "argument --seed: must be an integer >= 0, got -1"),
        (["bench", "--scans", "0"], "argument --scans: must be an integer >= 1, got 0"),
        (["latency-sweep", "seq", "--out", "o", "--delays-ms", "-1"], "argument --delays-ms: must be a number >= 0"),
    ],
)
def test_an_option_out_of_its_range_is_refused_before_any_work(args, fragment, capsys):
    with pytest.raises(SystemExit) as e:
        main(args)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err, err


def test_eval_times_and_stamps_files_name_their_line(sequence, tmp_path, capsys):
    kitti = sequence / "groundtruth_kitti.txt"  # --times stamps KITTI files
    times = tmp_path / "times.txt"
    times.write_text("0.1\nabc\n")
    assert (
        main(["eval", str(kitti), str(kitti), "--out", str(tmp_path / "e1"), "--times", str(times), "--no-plot"]) == 2
    )
    one_line_error(capsys, f"{times}:2: 'abc' is not a number of seconds")
    stamps = tmp_path / "stamps.txt"
    stamps.write_text("1700000000.1\ninf\n")
    tum = sequence / "groundtruth_scans.tum"
    assert (
        main(["eval", str(tum), str(tum), "--out", str(tmp_path / "e2"), "--scan-stamps", str(stamps), "--no-plot"])
        == 2
    )
    one_line_error(capsys, f"{stamps}:2: 'inf' is not a number of seconds")


# ---- clocks ---------------------------------------------------------------------------------


def test_scans_named_in_us_are_an_error_before_the_run(sequence, tmp_path, capsys):
    # before: the filter stepped 10 ms at a time across the 1.7e9 s between the clocks (a hang)
    seq = copy_of(sequence, tmp_path)
    for f in (seq / "lidar").iterdir():
        f.rename(f.with_name(f"{int(f.stem) // NS_PER_US}{f.suffix}"))
    assert main(["run", str(seq), "--out", str(tmp_path / "out"), "--no-plot", "--no-progress"]) == 2
    one_line_error(capsys, "they do not overlap", "are the scans", "stamped in us?")


def test_imu_stamped_in_us_is_an_error_before_the_run(sequence, tmp_path, capsys):
    # before: the run ended in "odometry_body.tum: no poses" without a summary
    seq = copy_of(sequence, tmp_path)
    rewrite_imu_stamps(seq, lambda t: t // NS_PER_US)
    assert main(["run", str(seq), "--out", str(tmp_path / "out"), "--no-plot", "--no-progress"]) == 2
    one_line_error(capsys, "IMU stamps span [1700000.000, 1700000.", "is imu.csv (or the IMU topic) stamped in us?")


def test_an_imu_offset_of_seconds_is_named_and_no_scan_is_dropped_as_busy(sequence, tmp_path, capsys):
    # before: 19 of 30 scans were dropped as "still busy", without a word about the clocks
    seq = copy_of(sequence, tmp_path)
    rewrite_imu_stamps(seq, lambda t: t + IMU_OFFSET_S * 1_000_000_000)
    out = tmp_path / "out"
    no_budget = ["--set", "registration.time_budget_factor=inf"]  # a loaded machine drops no frame either
    assert main(["run", str(seq), "--out", str(out), "--no-plot", "--no-progress", *no_budget]) == 0
    err = capsys.readouterr().err
    assert "the IMU starts 1.900 s after the first scan" in err and "an offset between the IMU and LiDAR clocks" in err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["dropped"] == 0 and summary["processed"] == summary["frames"]
    assert summary["mode"] == "lidar-inertial" and summary["fused"] > 0


# ---- outputs on interrupt ---------------------------------------------------------------------


def default_sigint() -> None:
    """In the child before exec: SIGINT back to its default action (Python then raises KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def wait_for_rows(path: Path, rows: int, process: subprocess.Popen) -> None:
    deadline = time.monotonic() + RUN_START_TIMEOUT_S
    while time.monotonic() < deadline and process.poll() is None:
        if path.exists() and len(path.read_text().splitlines()) > rows:
            return
        time.sleep(0.02)
    raise AssertionError(f"the run did not reach {rows} frames (exit {process.poll()})")


@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupted_run_keeps_its_summary_and_kitti_poses(sequence, tmp_path, sig, code):
    out = tmp_path / "out"
    # every registration runs its 50 iterations, each with its own searches (a kept match would make
    # the iterations after the first cheap): frames slow enough to interrupt mid-run
    slow = [
        "--set",
        "registration.convergence_norm=1e-300",
        "--set",
        "registration.max_iterations=50",
        "--set",
        "registration.correspondence_reuse_m=0",
    ]
    cmd = [sys.executable, "-m", "farlio.cli", "run", str(sequence), "--out", str(out), "--no-plot", "--no-progress"]
    # a shell starts background jobs with SIGINT ignored, and Python then keeps ignoring it (CI run
    # with `&`): the run is started with SIGINT at its default, as from a terminal
    process = subprocess.Popen(
        [*cmd, *slow, "--threads", "1"], stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint
    )
    try:
        wait_for_rows(out / "timing.csv", 3, process)
        process.send_signal(sig)
        _, err = process.communicate(timeout=EXIT_TIMEOUT_S)
    finally:
        process.kill()
    assert process.returncode == code, err
    assert "Traceback" not in err, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"] is True
    assert 2 <= summary["processed"] < summary["frames"]
    kitti = (out / "scans_lidar_kitti.txt").read_text().splitlines()
    tum = [line for line in (out / "scans_lidar.tum").read_text().splitlines() if not line.startswith("#")]
    assert len(kitti) == len(tum) == summary["processed"]
    first = [float(v) for v in kitti[0].split()]
    assert first == pytest.approx([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0], abs=1e-9)  # relative to the first pose
    assert all(math.isfinite(float(v)) for line in kitti for v in line.split())


# ---- the online odometry ----------------------------------------------------------------------


def test_online_warns_about_a_far_future_imu_stamp():
    """A sample 10,000 s ahead waits for the next: one that follows the others shows the stamp alone
    was wrong (the sample is dropped); two that follow it show the clock jumped (the fusion resets)."""
    t0 = 1_700_000_000_000_000_000
    future = t0 + 10_000 * 1_000_000_000
    for followed_by, expected in (
        ([t0 + 50_000_000], "from the samples around it: dropped"),
        (
            [future + 10_000_000, future + 20_000_000],
            "the fusion is reset",
        ),
    ):
        online = core.OnlineOdometry(core.Config(), core.SE3(), 9.81)
        for k in range(5):
            online.add_imu(core.ImuSample(t0 + k * 10_000_000, np.zeros(3), GRAVITY_UP))
        online.add_imu(core.ImuSample(future, np.zeros(3), GRAVITY_UP))
        assert online.take_warnings() == []  # held until the next sample
        for stamp in followed_by:
            online.add_imu(core.ImuSample(stamp, np.zeros(3), GRAVITY_UP))
        warnings = online.take_warnings()
        assert any("jumps by 9999.960 s" in w and expected in w for w in warnings), warnings
        assert online.take_warnings() == []
        assert len(online.take_odometry()) == 0
