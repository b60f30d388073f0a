"""Where along a run and along which axis the error is: the scan poses of a run against the ground
truth, aligned as `farlio eval` aligns them (the project's evaluation), with the RMS error per second
and per axis of the ground truth's frame, and the error along one axis every `--every` seconds; with
`--origin`, aligned at the first pose only (the drift from the start, a constant tilt included).
docs/fusion.md, "Other LiDARs" (the Mid-360 urban cut's 7 cm step along the track at 6.0-6.5 s):

  farlio simulate urban --lidar mid360 --start 10 --duration 10 --seed 1 --out cut
  farlio run cut --out lio --latency fixed
  farlio run cut --out lo --latency fixed --set fusion.enabled=false
  python figures/fusion_error_over_time.py cut/groundtruth_scans.tum lio/scans_body.tum lo/scans_body.tum"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from farlio import _core
from farlio.evaluation import make_options

NS_PER_S = 1e9


def errors(groundtruth: Path, estimate: Path, origin: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Seconds since the first associated pose and the aligned position errors (N x 3, m)."""
    read = _core.io.read_trajectory
    options = make_options(align_origin=origin)
    result = _core.eval.evaluate(read(estimate, "tum", None), read(groundtruth, "tum", None), options)
    stamps = np.asarray(result.stamps_ns, dtype=np.float64)
    diff = np.asarray(result.ape.aligned_positions_m) - np.asarray(result.groundtruth_positions_m)
    return (stamps - stamps[0]) / NS_PER_S, diff


def report(name: str, t: np.ndarray, diff: np.ndarray, axis: int, every_s: float) -> None:
    rms = np.sqrt((diff**2).sum(axis=1).mean())
    per_axis = np.sqrt((diff**2).mean(axis=0))
    print(f"{name}: APE {rms:.4f} m; RMS per axis x y z {per_axis[0]:.4f} {per_axis[1]:.4f} {per_axis[2]:.4f} m")
    seconds = [np.sqrt((diff[(t >= s) & (t < s + 1)] ** 2).sum(axis=1).mean()) for s in range(int(t[-1]) + 1)]
    print("  RMS per second (m): " + " ".join(f"{v:.3f}" for v in seconds))
    marks = np.arange(0.0, t[-1] + 1e-9, every_s)
    along = [diff[np.argmin(np.abs(t - m)), axis] for m in marks]
    print(f"  error along axis {'xyz'[axis]} every {every_s:g} s (m): " + " ".join(f"{v:+.3f}" for v in along))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("groundtruth", type=Path, help="TUM file of the true poses (groundtruth_scans.tum)")
    ap.add_argument("estimates", type=Path, nargs="+", help="TUM files of runs (scans_body.tum)")
    ap.add_argument("--axis", choices="xyz", default="x", help="the axis of the ground truth's frame to follow")
    ap.add_argument("--every", type=float, default=0.5, help="seconds between the printed errors along it")
    ap.add_argument("--origin", action="store_true", help="align at the first pose only, not over the whole run")
    args = ap.parse_args()
    for estimate in args.estimates:
        t, diff = errors(args.groundtruth, estimate, args.origin)
        report(str(estimate), t, diff, "xyz".index(args.axis), args.every)


if __name__ == "__main__":
    main()
