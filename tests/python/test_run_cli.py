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
