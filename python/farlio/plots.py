"""Pictures of a run, written into its output folder: trajectory.png (the estimated body path seen
from above, with the ground truth when there is one) and latency.png (histogram of the per-frame
processing time with its median and p99)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from farlio import _core

TRAJECTORY_PNG = "trajectory.png"
LATENCY_PNG = "latency.png"
HISTOGRAM_BINS = 40
FIGURE_SIZE_IN = (6.0, 4.5)
DPI = 110
MEDIAN_PERCENTILE, TAIL_PERCENTILE = 50, 99


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_trajectory(estimate: Path, path: Path, groundtruth: Path | None = None) -> None:
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=FIGURE_SIZE_IN)
    for file, label, style in ((groundtruth, "ground truth", "k--"), (estimate, "estimate", "C0-")):
        if file is None or not Path(file).exists():
            continue
        poses = _core.io.read_trajectory(Path(file)).matrices()
        if len(poses):
            ax.plot(poses[:, 0, 3], poses[:, 1, 3], style, label=label, linewidth=1.2)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend()
    ax.set_title(f"trajectory: {Path(estimate).name}")
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def plot_latency(timing_csv: Path, path: Path) -> None:
    with open(timing_csv, newline="") as f:
        totals = [float(r["total_ms"]) for r in csv.DictReader(f) if r.get("total_ms")]
    if not totals:
        return
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=FIGURE_SIZE_IN)
    ax.hist(totals, bins=HISTOGRAM_BINS, color="C0", alpha=0.8)
    for q, style in ((MEDIAN_PERCENTILE, "k-"), (TAIL_PERCENTILE, "r--")):
        v = float(np.percentile(totals, q))
        ax.axvline(v, color=style[0], linestyle=style[1:], label=f"p{q} {v:.2f} ms")
    ax.set_xlabel("processing time per frame [ms]")
    ax.set_ylabel("frames")
    ax.legend()
    ax.set_title(f"latency ({len(totals)} frames)")
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def plot_run(out_dir: Path, groundtruth: str | Path | None = None) -> None:
    """Writes trajectory.png and latency.png from a run folder's scans_body.tum and timing.csv."""
    out_dir = Path(out_dir)
    plot_trajectory(out_dir / "scans_body.tum", out_dir / TRAJECTORY_PNG, Path(groundtruth) if groundtruth else None)
    plot_latency(out_dir / "timing.csv", out_dir / LATENCY_PNG)
