"""What the figure scripts share: a work folder that goes away afterwards, generated sequences in it
(on disk, or served from memory), the configuration of the LIO and of LiDAR-only with `--set`
overrides, the deterministic replay of `farlio run` (fixed 20 ms latency, the accuracy tables'
model), the accuracy figures of a run's summary, the columns of its timing.csv, and markdown table
rows.

The scripts import it as `harness`: Python puts the folder of the script it runs first on sys.path,
so `python figures/NAME.py` finds it from any working directory."""

from __future__ import annotations

import contextlib
import csv
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from farlio import _core
from farlio.config import load_config
from farlio.datasets import open_dataset
from farlio.datasets.base import Dataset
from farlio.datasets.generated import GeneratedDataset
from farlio.mapping import MapOptions
from farlio.runner import replay_options, run_dataset
from farlio.simulation import generate
from farlio.timing_csv import TIMING_CSV

#: the replay latency of every accuracy figure in the docs (s)
FIXED_LATENCY_S = 0.02
LIDAR_ONLY = "fusion.enabled=false"
#: the overrides that make each mode, applied after the script's own (a mode always holds)
MODES: dict[str, list[str]] = {"lio": [], "lidar-only": [LIDAR_ONLY]}


@contextlib.contextmanager
def work_folder(path: Path | None = None, prefix: str = "farlio-figures-") -> Iterator[Path]:
    """`path` (created if missing, kept), or a new temporary folder removed on leaving."""
    if path is not None:
        path.mkdir(parents=True, exist_ok=True)
        yield path
        return
    tmp = Path(tempfile.mkdtemp(prefix=prefix))
    try:
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def generated_sequence(work: Path, profile: str, seed: int = 1, duration_s: float | None = None, **sim: Any) -> Path:
    """The folder of a sequence generated into `work` (`farlio simulate`'s layout), written once: a
    folder already holding it (its meta.yaml) is reused. sim: further make_config arguments."""
    length = "default" if duration_s is None else f"{duration_s:g}s"
    folder = work / f"{profile}_seed{seed}_{length}"
    if not (folder / "meta.yaml").exists():
        generate(profile, folder, seed=seed, duration_s=duration_s, **sim)
    return folder


def generated_dataset(profile: str, seed: int, duration_s: float, work: Path, **sim: Any) -> GeneratedDataset:
    """A generated sequence served from memory (no scans on disk: a racetrack lap is ~7 GB of PCD),
    its ground truth in `work`/PROFILE-SEED. sim: further make_config arguments (lidar, ...)."""
    return GeneratedDataset(profile, seed, duration_s, work / f"{profile}-{seed}", **sim)


def recording_scans(path: str | Path) -> list:
    """Every scan of a recording (any format `farlio run` reads), loaded up front."""
    ds = open_dataset(path)
    return [ds.scan(i) for i in range(len(ds))]


def mode_overrides(overrides: Sequence[str], mode: str = "lio") -> list[str]:
    """`--set` overrides ("name=value") followed by those of the mode (MODES)."""
    return [*overrides, *MODES[mode]]


def config(overrides: Sequence[str] = (), mode: str = "lio") -> _core.Config:
    """The defaults with the overrides and the mode's, as `farlio run --set ...` builds them."""
    return load_config(None, mode_overrides(overrides, mode))


def pipeline_config(threads: int, overrides: dict[str, str] | None = None) -> _core.Config:
    """The scan pipeline's config for timing: `threads` threads on the CPU, then the overrides."""
    cfg = _core.Config()
    cfg.set("num_threads", str(threads))
    cfg.set("device", "cpu")
    for name, value in (overrides or {}).items():
        cfg.set(name, value)
    return cfg


def fixed_latency() -> _core.ReplayOptions:
    """The replay options of the accuracy figures: every scan processed FIXED_LATENCY_S after its end."""
    return replay_options("fixed", FIXED_LATENCY_S)


def run(dataset: Dataset | str | Path, out: Path, cfg: _core.Config, maps: MapOptions | None = None) -> dict:
    """`farlio run`'s code (run_dataset) over a dataset or a recording's folder, with the fixed
    latency, no progress bar and no plots; returns the summary (summary.json in `out`)."""
    if not isinstance(dataset, Dataset):
        dataset = open_dataset(dataset)
    return run_dataset(dataset, out, cfg, progress=False, plot=False, maps=maps, options=fixed_latency())


def ape_m(accuracy: dict) -> float:
    """The aligned translation RMSE (m) of an accuracy block (summary["accuracy"], evaluate_files)."""
    return accuracy["ape"]["translation_m"]["rmse"]


def rpe_pct(accuracy: dict) -> float:
    """The KITTI-style relative translation error (%) of an accuracy block."""
    return accuracy["kitti_rpe"]["translation_pct"]


def timing_rows(run_dir: Path, column: str | None = None) -> list[dict[str, str]]:
    """The rows of a run's timing.csv; with `column`, only those where it has a value."""
    with open(run_dir / TIMING_CSV, newline="") as f:
        return [r for r in csv.DictReader(f) if column is None or r.get(column)]


def floats(rows: list[dict[str, str]], column: str) -> list[float]:
    """A timing.csv column's values, rows without one left out."""
    return [float(r[column]) for r in rows if r[column]]


def table_row(*cells: Any) -> str:
    """A markdown table row (without the outer bars): the cells as they are, joined by " | "."""
    return " | ".join(str(c) for c in cells)
