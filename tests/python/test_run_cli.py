"""`farlio run` options for recordings: documented in --help, and --view without rerun-sdk is a
clear error, not a traceback."""

from __future__ import annotations

import sys

import pytest

pytest.importorskip("farlio._core")

from farlio.cli import build_parser, main  # noqa: E402

RECORDING_OPTIONS = [
    "--lidar-topic",
    "--imu-topic",
    "--calib",
    "--meta",
    "--time-field",
    "--time-unit",
    "--header-stamp",
    "--no-imu",
    "--view",
    "--no-plot",
    "--format",
    "--gt",
    "--out",
]


def test_run_help_documents_every_recording_option(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["run", "--help"])
    text = capsys.readouterr().out
    for option in RECORDING_OPTIONS:
        assert option in text
    for fmt in ("rosbag", "ouster", "kitti-raw", "mulran"):
        assert fmt in text


def test_view_without_rerun_is_a_clear_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun raises ImportError
    (tmp_path / "scans").mkdir()
    assert main(["run", str(tmp_path / "scans"), "--out", str(tmp_path / "out"), "--view"]) == 2
    err = capsys.readouterr().err
    assert "--view needs the 'rerun-sdk' package" in err and "Traceback" not in err


def test_unknown_layout_lists_the_formats(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert main(["run", str(tmp_path / "empty"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "cannot tell its format" in err and "ROS 1 .bag" in err and "Ouster .pcap" in err


def test_demo_runs_on_a_generated_sequence_without_writing_its_scans(tmp_path):
    """`farlio demo`: the LIO on 8 s of the urban drive served from memory. It writes `farlio run
    --save-map`'s files and the ground truth, tracks the exact ground truth to centimetres, and puts
    no scan on disk (the same 8 s as `farlio simulate` writes are about 190 MB)."""
    import json

    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--duration", "8", "--no-plot", "--no-progress"]) == 0
    for name in ("scans_body.tum", "odometry_body.tum", "map.pcd", "summary.json", "groundtruth/groundtruth.tum"):
        assert (out / name).is_file(), name
    summary = json.loads((out / "summary.json").read_text())
    assert summary["processed"] == summary["frames"] == 80
    assert summary["fusion"]["initialization"]["mode"] == "standstill"
    # every LiDAR result after the one that started the filter is checked against the prediction
    innovation = summary["fusion"]["innovation"]
    assert set(innovation) == {"pose", "velocity"}
    assert innovation["pose"]["dof"] == 6 and innovation["pose"]["count"] >= 75
    assert 0.0 < innovation["pose"]["mean_nis_per_dof"] < 1.0 and innovation["pose"]["share_beyond_95"] <= 0.05
    assert summary["accuracy"]["ape"]["translation_m"]["rmse"] < 0.03
    assert summary["accuracy_odometry"]["ape"]["translation_m"]["rmse"] < 0.03
    size = sum(f.stat().st_size for f in out.rglob("*") if f.is_file())
    assert size < 20e6, f"{size / 1e6:.1f} MB"
