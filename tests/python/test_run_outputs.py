"""What `run_dataset` writes: timing.csv rows built from named fields (every row holds exactly the
header's columns, in its order), the keys of summary.json and its accuracy on a standing start."""

from __future__ import annotations

import csv
import json
from types import SimpleNamespace

import pytest

core = pytest.importorskip("farlio._core")

from farlio.datasets import open_dataset  # noqa: E402
from farlio.runner import replay_options, run_dataset  # noqa: E402
from farlio.simulation import generate  # noqa: E402
from farlio.timing_csv import DEGENERACY_COLUMNS, TIMING_COLUMNS, TimingCsv, timing_row  # noqa: E402

SIM_DURATION_S = 1.0
SUMMARY_KEYS = [
    "dataset",
    "mode",
    "frames",
    "processed",
    "skipped",
    "dropped",
    "registered",
    "fused",
    "not_fused",
    "degenerate",
    "registration_failed",
    "map_restarts",
    "converged_fraction",
    "latency_ms",
    "wall_s",
    "rate_hz",
    "device",
    "map_memory_bytes",
    "threads",
    "fusion",
    "accuracy",
    "accuracy_odometry",
    "voxel_size_m",
]
LATENCY_KEYS = ["median", "p99", "max", "mean"]
#: the aligned rotation error of the scan poses and of the odometry (Umeyama alone: tens of degrees)
MAX_ROTATION_APE_DEG = 1.0


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    path = tmp_path_factory.mktemp("seq") / "urban"
    generate("urban", path, duration_s=SIM_DURATION_S)
    return path


@pytest.fixture(scope="module")
def run(sequence, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    summary = run_dataset(open_dataset(sequence), out, progress=False, plot=False, options=replay_options("zero"))
    return out, summary


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


def test_every_timing_row_has_the_header_columns(run):
    out, summary = run
    header, *rows = read_rows(out / "timing.csv")
    assert header == TIMING_COLUMNS
    assert len(rows) == summary["frames"]
    for row in rows:
        assert len(row) == len(header)
        filled = dict(zip(header, row))
        # the degeneracy columns are empty only for a scan that was not registered (the first)
        optional = ["drop_reason"] + (DEGENERACY_COLUMNS if filled["registered"] == "0" else [])
        assert all(filled[c] != "" for c in TIMING_COLUMNS if c not in optional), row
    assert sum(row[header.index("translation_std_max_m")] != "" for row in rows) == summary["registered"]


def test_a_processed_frame_fills_every_column_in_order(sequence):
    ds = open_dataset(sequence)
    odometry = core.Odometry(core.Config(), ds.T_imu_lidar(), ds.gravity_m_s2(), ds.imu(), replay_options("zero"))
    scan = ds.scan(0)
    frame = odometry.process(scan)
    assert frame.processed
    row = timing_row(0, scan, frame)
    assert list(row) == TIMING_COLUMNS
    assert row["stamp_ns"] == scan.end_stamp_ns and row["stage_clock"] in ("wall", "cuda_events")


def test_a_dropped_frame_keeps_its_index_stamp_and_reason(tmp_path):
    scan = SimpleNamespace(end_stamp_ns=1_700_000_000_000_000_000)
    dropped = SimpleNamespace(processed=False, drop_reason="worker busy")
    with TimingCsv(tmp_path / "timing.csv") as timing:
        timing.write(7, scan, dropped)
        # flushed as it goes: the row is on disk before the file is closed
        assert len(read_rows(tmp_path / "timing.csv")) == 2
    header, row = read_rows(tmp_path / "timing.csv")
    assert row == ["7", str(scan.end_stamp_ns)] + [""] * (len(header) - 3) + ["worker busy"]


def test_summary_json_keys(run):
    out, _ = run
    summary = json.loads((out / "summary.json").read_text())
    assert list(summary) == SUMMARY_KEYS
    assert list(summary["latency_ms"]) == LATENCY_KEYS
    assert summary["processed"] == summary["frames"] > 0


def test_standing_start_rotation_error_is_not_an_alignment_artefact(run):
    """The first second of urban stands still: the positions fix no rotation, so the alignment takes it
    from the orientations and the aligned rotation error stays the small true one."""
    _, summary = run
    for key in ("accuracy", "accuracy_odometry"):
        ape = summary[key]["ape"]
        assert ape["alignment"]["method"] == "orientation", key
        assert ape["rotation_deg"]["rmse"] < MAX_ROTATION_APE_DEG, key
