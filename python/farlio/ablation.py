"""The paper's studies on a recording with ground truth: the component ablation (Table III) and
the added-latency sweep (APE stable up to a threshold, then rising)."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

from ._core import Config
from .config import load_config
from .datasets import open_dataset
from .runner import replay_options, run_dataset

#: (name, overrides): each row adds one component, as in the paper's Table III
ABLATION_ROWS = [
    (
        "none",
        [
            "fusion.enabled=false",
            "fusion.delay.compensation=false",
            "preprocess.undistort=false",
            "registration.sparsity_aware=false",
            "density.enabled=false",
        ],
    ),
    (
        "EKF",
        [
            "fusion.delay.compensation=false",
            "preprocess.undistort=false",
            "registration.sparsity_aware=false",
            "density.enabled=false",
        ],
    ),
    ("EKF+DC", ["preprocess.undistort=false", "registration.sparsity_aware=false", "density.enabled=false"]),
    ("EKF+DC+MU", ["registration.sparsity_aware=false", "density.enabled=false"]),
    ("EKF+DC+MU+SA", ["density.enabled=false"]),
    ("EKF+DC+MU+SA+ASMD", []),
]
NAN = float("nan")


def _accuracy(summary: dict[str, Any]) -> tuple[float, float]:
    """APE RMSE (m) and KITTI-style RPE (%) of the final output: the 100 Hz odometry when fused."""
    acc = summary.get("accuracy_odometry") or summary.get("accuracy")
    if not acc:
        return NAN, NAN
    return acc["ape"]["translation_m"]["rmse"], acc["kitti_rpe"]["translation_pct"]


def ablate(sequence: Path, out_dir: Path, *, latency: str = "measured", max_frames: int | None = None) -> list[dict]:
    """Runs every row of ABLATION_ROWS; writes ablation.csv and ablation.md into out_dir."""
    rows = []
    for name, overrides in ABLATION_ROWS:
        s = run_dataset(
            open_dataset(sequence),
            out_dir / name.replace("+", "_"),
            load_config(None, overrides),
            progress=False,
            plot=False,
            options=replay_options(latency, 0.0),
            max_frames=max_frames,
        )
        ape, rpe = _accuracy(s)
        rows.append(
            {
                "components": name,
                "ape_m": ape,
                "rpe_pct": rpe,
                "dropped": s["dropped"],
                "median_ms": s["latency_ms"]["median"],
            }
        )
    _write(out_dir, "ablation", rows)
    return rows


def latency_sweep(
    sequence: Path,
    out_dir: Path,
    delays_s: list[float],
    *,
    max_frames: int | None = None,
    plot: bool = True,
    config: Config | None = None,
    fixed: bool = False,
) -> list[dict]:
    """Runs the LIO (config, default: the defaults) with each added delay on top of the measured
    latency (fixed: each delay is the whole latency, a deterministic run); writes
    latency_sweep.csv, latency_sweep.md and (plot) latency_sweep.png into out_dir."""
    config = config if config is not None else load_config(None)
    rows = []
    for d in delays_s:
        s = run_dataset(
            open_dataset(sequence),
            out_dir / f"delay_{d * 1e3:.0f}ms",
            config,
            progress=False,
            plot=False,
            options=replay_options("fixed", d, 0.0) if fixed else replay_options("measured", 0.0, d),
            max_frames=max_frames,
        )
        ape, rpe = _accuracy(s)
        rows.append({"added_delay_ms": d * 1e3, "ape_m": ape, "rpe_pct": rpe, "dropped": s["dropped"]})
    _write(out_dir, "latency_sweep", rows)
    if plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot([r["added_delay_ms"] for r in rows], [r["ape_m"] for r in rows], "o-")
        ax.set_xlabel("added delay [ms]")
        ax.set_ylabel("APE RMSE [m]")
        ax.set_title(Path(sequence).name)
        ax.grid(True)
        fig.tight_layout()
        fig.savefig(out_dir / "latency_sweep.png", dpi=120)
        plt.close(fig)
    return rows


def _write(out_dir: Path, stem: str, rows: list[dict]) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / f"{stem}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    keys = list(rows[0])
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(f"{v:.3f}" if isinstance(v, float) else str(v) for v in r.values()) + " |")
    (out_dir / f"{stem}.md").write_text("\n".join(lines) + "\n")
