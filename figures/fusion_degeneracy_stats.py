#!/usr/bin/env python3
"""The figures behind the degeneracy threshold (docs/fusion.md, "Degeneracy": why 0.05 m) and the
kernel with the fusion's guess. Per run, what the registration's thresholds saw, from the timing.csv
of `farlio run`: the
adaptive sigma and the Cauchy kernel scale used (docs/fusion.md: the kernel with the
fusion's guess), and the degeneracy statistics (the largest translation std, the largest std per
matched point = translation_std_max_m * sqrt(inliers), the largest rotation std, the flagged scans,
and the per-point std of the scans whose std exceeds --bare-std-m: the tunnel's bare section).

Usage: python figures/fusion_degeneracy_stats.py RUN_DIR [RUN_DIR ...] [--bare-std-m 0.06]
(RUN_DIR: the --out of `farlio run SEQ --out RUN_DIR --latency fixed --fixed-latency 0.02`)."""

from __future__ import annotations

import argparse
import math
import statistics
from pathlib import Path

from harness import timing_rows


def _floats(rows: list[dict[str, str]], column: str) -> list[float]:
    return [float(r[column]) for r in rows]


def stats(run: Path, bare_std_m: float) -> str:
    rows = timing_rows(run, "translation_std_max_m")
    if not rows:
        return f"{run.name}: no registered scan with degeneracy columns"
    sigma, kernel = _floats(rows, "sigma_m"), _floats(rows, "kernel_scale_m")
    std, rot = _floats(rows, "translation_std_max_m"), _floats(rows, "rotation_std_max_rad")
    per_point = [s * math.sqrt(max(1.0, float(r["inliers"]))) for s, r in zip(std, rows, strict=True)]
    flagged = sum(1 for r in rows if int(r["degenerate_directions"] or 0) > 0)
    bare = sorted(p for p, s in zip(per_point, std, strict=True) if s > bare_std_m)
    bare_text = f"{len(bare)} scans, per-point min {bare[0]:.2f} p5 {bare[len(bare) // 20]:.2f}" if bare else "none"
    return (
        f"{run.name}: {len(rows)} scans | sigma m median {statistics.median(sigma):.3f} min {min(sigma):.3f} | "
        f"kernel m median {statistics.median(kernel):.3f} | std m max {max(std):.4f} | per-point max "
        f"{max(per_point):.2f} | rotation std rad max {max(rot):.4f} | flagged {flagged} | std > {bare_std_m} m: "
        f"{bare_text}"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+", type=Path, help="run folders (each with timing.csv)")
    p.add_argument("--bare-std-m", type=float, default=0.06, help="scans whose std exceeds this count as bare")
    args = p.parse_args()
    for run in args.runs:
        print(stats(run, args.bare_std_m))


if __name__ == "__main__":
    main()
