"""--device on the command line: auto falls back to the CPU with a one-line message when no GPU
is present; cuda without one is a clear error (exit 2); a bad name is rejected by argparse."""

from __future__ import annotations

import farlio
import pytest
from farlio import _core
from farlio.cli import main

BENCH = ["bench", "--profile", "handheld", "--scans", "2", "--no-kiss"]
no_gpu = pytest.mark.skipif(farlio.cuda_device_count() > 0, reason="a CUDA device is present")


@no_gpu
def test_auto_falls_back_with_one_line(capsys):
    assert main(BENCH + ["--device", "auto"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    fallback = [line for line in err if "running on the CPU" in line]
    assert len(fallback) == 1, err
    assert fallback[0].startswith("farlio: device auto:")


@no_gpu
def test_cuda_without_gpu_is_an_error(capsys):
    assert main(BENCH + ["--device", "cuda"]) == 2
    err = capsys.readouterr().err
    assert "device cuda was requested" in err
    assert "--device auto or cpu" in err


def test_cpu_runs_silently(capsys):
    assert main(BENCH + ["--device", "cpu"]) == 0
    captured = capsys.readouterr()
    assert "running on the CPU" not in captured.err
    assert "farlio on cpu" in captured.out


def test_unknown_device_is_rejected():
    with pytest.raises(SystemExit):
        main(BENCH + ["--device", "gpu"])


def test_config_field_device():
    cfg = _core.Config()
    assert cfg.get("device") == "auto"
    cfg.set("device", "cpu")
    assert cfg.get("device") == "cpu"
    with pytest.raises(ValueError, match="expected auto, cpu or cuda"):
        cfg.set("device", "tpu")
