"""Pictures of a run, written into its output folder: trajectory.png (the estimated body path seen
from above, with the ground truth when there is one), latency.png (histogram of the per-frame
processing time with its median and p99) and, with --save-map, map.png (the whole map from above,
coloured by height, with the path on top)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from farlio import _core

TRAJECTORY_PNG = "trajectory.png"
LATENCY_PNG = "latency.png"
MAP_PNG = "map.png"
#: map.png draws at most this many points (an even subsample of a larger map)
MAP_PNG_MAX_POINTS = 400_000
#: the colour scale of the height spans these percentiles (a few high points do not wash it out)
HEIGHT_PERCENTILES = (2, 98)
MAP_FIGURE_SIZE_IN = (8.0, 8.0)
MAP_POINT_SIZE = 0.3
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


def plot_map(points: np.ndarray, trajectory: Path, path: Path, loops: np.ndarray | None = None) -> None:
    """map.png: the map's points (N, 3, world frame) from above coloured by height, with the
    trajectory (a TUM file in the same frame) drawn on top, and loops ((M, 2, 2): the xy of both
    ends of each accepted loop) as lines between the places they join."""
    plt = _pyplot()
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) > MAP_PNG_MAX_POINTS:
        pts = pts[:: int(np.ceil(len(pts) / MAP_PNG_MAX_POINTS))]
    fig, ax = plt.subplots(figsize=MAP_FIGURE_SIZE_IN)
    if len(pts):
        order = np.argsort(pts[:, 2])  # high points drawn last (roofs over the ground)
        lo, hi = np.percentile(pts[:, 2], HEIGHT_PERCENTILES)
        sc = ax.scatter(
            pts[order, 0],
            pts[order, 1],
            c=pts[order, 2],
            s=MAP_POINT_SIZE,
            cmap="viridis",
            vmin=lo,
            vmax=max(hi, lo + 1e-3),
            linewidths=0,
            rasterized=True,
        )
        fig.colorbar(sc, ax=ax, shrink=0.7, label="height z [m]")
    if Path(trajectory).exists():
        poses = _core.io.read_trajectory(Path(trajectory)).matrices()
        if len(poses):
            ax.plot(poses[:, 0, 3], poses[:, 1, 3], "r-", linewidth=1.2, label="trajectory")
            ax.plot(poses[0, 0, 3], poses[0, 1, 3], "ro", markersize=4)
    if loops is not None and len(loops):
        for i, (a, b) in enumerate(np.asarray(loops)):
            ax.plot([a[0], b[0]], [a[1], b[1]], "m-o", markersize=3, linewidth=1.5, label="loop" if i == 0 else None)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper right")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="box")  # the axes fit the map, not the square figure
    ax.set_title(f"map: {len(points)} points")
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
