"""timing.csv of a run: one row a frame, built from named fields so that no column can drift from
the header; written line by line, so a run that dies keeps every row it produced."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

from farlio._core import NS_PER_S

TIMING_CSV = "timing.csv"
MS_PER_S = 1e3
NS_PER_MS = NS_PER_S / MS_PER_S
#: timing.csv's stage_clock: the stage times are wall clock (CPU) or CUDA events (GPU timeline)
STAGE_CLOCKS = {False: "wall", True: "cuda_events"}
#: how well the registration constrained the pose (empty for a scan that was not registered)
DEGENERACY_COLUMNS = ["translation_std_max_m", "translation_weak_axis", "rotation_std_max_rad", "degenerate_directions"]
TIMING_COLUMNS = [
    "frame",
    "stamp_ns",
    "input_points",
    "kept_points",
    "source_points",
    "registered",
    "converged",
    "iterations",
    "inliers",
    "inlier_fraction",
    "lost",
    "sigma_m",
    "kernel_scale_m",
    "density_limit",
    "map_voxels",
    "map_points",
    "preprocess_ms",
    "covariance_ms",
    "registration_ms",
    "map_update_ms",
    "total_ms",
    "stage_clock",
    "fused",
    "guess_from_fusion",
    "latency_ms",
    *DEGENERACY_COLUMNS,
    "drop_reason",
]


def _ms(seconds: float) -> str:
    return f"{seconds * MS_PER_S:.3f}"


def timing_row(index: int, scan: Any, frame: Any) -> dict[str, Any]:
    """The row of scan number `index` and its OdometryFrame. A frame that was not processed has
    only its index, stamp and drop reason (the other columns stay empty)."""
    if not frame.processed:
        return {"frame": index, "stamp_ns": scan.end_stamp_ns, "drop_reason": frame.drop_reason}
    r, t = frame.scan, frame.scan.timings
    return {
        "frame": index,
        "stamp_ns": r.stamp_ns,
        "input_points": r.input_points,
        "kept_points": r.kept_points,
        "source_points": r.source_points,
        "registered": int(r.registered),
        "converged": int(r.converged),
        "iterations": r.iterations,
        "inliers": r.inliers,
        "inlier_fraction": f"{r.inlier_fraction:.4f}",
        "lost": int(r.lost),
        "sigma_m": f"{r.sigma_m:.4f}",
        "kernel_scale_m": f"{r.kernel_scale_m:.4f}",
        "density_limit": r.density_limit,
        "map_voxels": r.map_voxels,
        "map_points": r.map_points,
        "preprocess_ms": _ms(t.preprocess_s),
        "covariance_ms": _ms(t.covariance_s),
        "registration_ms": _ms(t.registration_s),
        "map_update_ms": _ms(t.map_update_s),
        "total_ms": _ms(t.total_s),
        "stage_clock": STAGE_CLOCKS[t.device_timed],
        "fused": int(frame.fused),
        "guess_from_fusion": int(frame.guess_from_fusion),
        "latency_ms": f"{(frame.available_ns - frame.started_ns) / NS_PER_MS:.3f}",
        **_degeneracy_fields(frame.degeneracy),
        "drop_reason": frame.drop_reason,
    }


def _degeneracy_fields(d: Any) -> dict[str, Any]:
    """The registration's largest translation std with its body-frame direction, its largest
    rotation std, and how many directions exceed the degeneracy thresholds (docs/fusion.md)."""
    if d is None:
        return dict.fromkeys(DEGENERACY_COLUMNS, "")
    axis = d.translation_axes[:, 0]
    axis = axis if axis[abs(axis).argmax()] >= 0 else -axis  # the sign is arbitrary: largest component positive
    return {
        "translation_std_max_m": f"{d.translation_std_m[0]:.4g}",
        "translation_weak_axis": " ".join(f"{v:+.3f}" for v in axis),
        "rotation_std_max_rad": f"{d.rotation_std_rad[0]:.4g}",
        "degenerate_directions": d.degenerate_translations + d.degenerate_rotations,
    }


class TimingCsv:
    """timing.csv under construction: the header at once, then one flushed row per frame."""

    def __init__(self, path: Path):
        self._file = open(path, "w", newline="", buffering=1)
        self._writer = csv.DictWriter(self._file, fieldnames=TIMING_COLUMNS, restval="")
        self._writer.writeheader()

    def write(self, index: int, scan: Any, frame: Any) -> None:
        self._writer.writerow(timing_row(index, scan, frame))

    def __enter__(self) -> TimingCsv:
        return self

    def __exit__(self, *exc: Any) -> None:
        self._file.close()
