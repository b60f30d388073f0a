"""Trajectory evaluation against ground truth: the C++ readers and metrics, eval.json and eval.png.

The metrics themselves (association, APE, KITTI-style and evo-style RPE, coverage) are computed by
``farlio._core.eval.evaluate``; see docs/evaluation.md for their definitions.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from farlio import _core
from farlio._core import NS_PER_S
from farlio.cli_args import non_negative_float, positive_float, positive_int

#: trajectory file formats ("auto": TUM or KITTI by the column count), as the C++ reader names them
FORMATS = tuple(_core.io.TRAJECTORY_FORMATS)
RPE_UNITS = ("frames", "m")
JSON_NAME = "eval.json"
PLOT_NAME = "eval.png"
PLOT_SIZE_IN = (12.0, 5.0)
PLOT_DPI = 120


def make_options(
    *,
    max_time_diff_s: float | None = None,
    nearest: bool = False,
    align_scale: bool = False,
    align_origin: bool = False,
    kitti_step: int | None = None,
    segment_lengths_m: list[float] | None = None,
    rpe_delta: float | None = None,
    rpe_unit: str = "frames",
    rpe_all_pairs: bool = False,
    rpe_pairs_from_estimate: bool = False,
    scan_stamps_ns: Sequence[int] | None = None,
):
    """EvalOptions from keyword arguments; None keeps the C++ default."""
    ev = _core.eval
    o = ev.EvalOptions()
    assoc = o.association
    if max_time_diff_s is not None:
        assoc.max_time_diff_s = max_time_diff_s
    assoc.mode = ev.AssociationMode.NEAREST if nearest else ev.AssociationMode.INTERPOLATE
    o.association = assoc
    if align_scale and align_origin:
        raise ValueError("an alignment at the origin has no scale: align_scale and align_origin exclude each other")
    o.align_with_scale = align_scale
    o.ape_alignment = ev.ApeAlignment.ORIGIN if align_origin else ev.ApeAlignment.LEAST_SQUARES
    kitti = o.kitti
    if kitti_step is not None:
        kitti.step_frames = kitti_step
    if segment_lengths_m:
        kitti.segment_lengths_m = list(segment_lengths_m)
    o.kitti = kitti
    rpe = o.rpe
    if rpe_delta is not None:
        rpe.delta = rpe_delta
    if rpe_unit not in RPE_UNITS:
        raise ValueError(f"unknown RPE delta unit {rpe_unit!r}; use one of {RPE_UNITS}")
    rpe.unit = ev.DeltaUnit.METERS if rpe_unit == "m" else ev.DeltaUnit.FRAMES
    rpe.all_pairs = rpe_all_pairs
    rpe.pairs_from_groundtruth = not rpe_pairs_from_estimate
    o.rpe = rpe
    if scan_stamps_ns is not None:
        o.scan_stamps_ns = [int(s) for s in scan_stamps_ns]
    return o


def alignment_method_name(method) -> str:
    """'umeyama' (positions), 'umeyama_orientation' (positions on a line: the rotation about it from
    the orientations), 'orientation' (positions at one point) or 'origin' (the first poses made one),
    as eval.json states it."""
    return method.name.lower()


def _stats(s) -> dict[str, float]:
    return {"count": s.count, "rmse": s.rmse, "mean": s.mean, "median": s.median, "max": s.max}


def result_to_dict(r) -> dict[str, Any]:
    """The JSON-ready summary of an EvaluationResult (no per-pose arrays)."""
    k = r.kitti_rpe
    return {
        "estimate_poses": r.estimate_poses,
        "groundtruth_poses": r.groundtruth_poses,
        "associated_poses": r.associated_poses,
        "coverage": r.coverage,
        "groundtruth_path_length_m": r.groundtruth_path_length_m,
        "ape": {
            "translation_m": _stats(r.ape.translation_m),
            "rotation_deg": _stats(r.ape.rotation_deg),
            "translation_raw_m": _stats(r.ape.translation_raw_m),
            "rotation_raw_deg": _stats(r.ape.rotation_raw_deg),
            "alignment": {
                "method": alignment_method_name(r.ape.alignment.method),
                "matrix": r.ape.alignment.transform.matrix().tolist(),
                "scale": r.ape.alignment.scale,
                "rank_deficient": r.ape.alignment.rank_deficient,
            },
        },
        "kitti_rpe": {
            "segment_lengths_m": list(k.segment_lengths_m),
            "segment_count": k.segment_count,
            "translation_pct": k.translation_pct,
            "rotation_deg_per_100m": k.rotation_deg_per_100m,
            "per_length": [
                {
                    "length_m": p.length_m,
                    "segment_count": p.segment_count,
                    "translation_pct": p.translation_pct,
                    "rotation_deg_per_100m": p.rotation_deg_per_100m,
                }
                for p in k.per_length
            ],
        },
        "rpe": {
            "pair_count": len(r.rpe.pairs),
            "translation_m": _stats(r.rpe.translation_m),
            "rotation_deg": _stats(r.rpe.rotation_deg),
        },
    }


def plot_result(r, path: Path, title: str = "") -> None:
    """Top view of the aligned estimate over the ground truth, and the aligned APE over time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    gt = r.groundtruth_positions_m
    est = r.ape.aligned_positions_m
    stamps = r.stamps_ns
    t_s = (stamps - stamps[0]) / NS_PER_S
    fig, (top, err) = plt.subplots(1, 2, figsize=PLOT_SIZE_IN)
    top.plot(gt[:, 0], gt[:, 1], "k-", label="ground truth")
    top.plot(est[:, 0], est[:, 1], "r-", label="estimate (aligned)")
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_title("top view")
    top.legend()
    err.plot(t_s, r.ape.translation_errors_m, "b-")
    err.set_xlabel("time [s]")
    err.set_ylabel("APE translation [m]")
    err.set_title(f"APE (aligned), RMSE {r.ape.translation_m.rmse:.3f} m")
    err.grid(True)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=PLOT_DPI)
    plt.close(fig)


def _json_safe(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_safe(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_safe(v) for v in value]
    return value


def evaluate_files(
    estimate: Path,
    groundtruth: Path,
    out_dir: Path | None = None,
    *,
    fmt: str = "auto",
    plot: bool = True,
    estimate_times: Path | None = None,
    groundtruth_times: Path | None = None,
    scan_stamps: Path | None = None,
    **options,
) -> dict[str, Any]:
    """Evaluates an estimated trajectory file against a ground-truth file.

    fmt: "tum", "kitti" or "auto" (by column count). KITTI files take a times file each; one given
    for only one of them is used for both. scan_stamps: a file whose first column holds the scan
    stamps in seconds (coverage reference; default the ground-truth stamps). ``options`` go to
    make_options(). Writes eval.json (and eval.png if plot) into out_dir when given.
    """
    estimate, groundtruth = Path(estimate), Path(groundtruth)
    est_times = estimate_times or groundtruth_times
    gt_times = groundtruth_times or estimate_times
    est = _core.io.read_trajectory(estimate, fmt, est_times)
    gt = _core.io.read_trajectory(groundtruth, fmt, gt_times)
    if scan_stamps is not None:
        options["scan_stamps_ns"] = _core.io.read_stamps(scan_stamps)
    result = _core.eval.evaluate(est, gt, make_options(**options))
    summary = result_to_dict(result)
    summary["estimate_file"] = str(estimate)
    summary["groundtruth_file"] = str(groundtruth)
    summary = _json_safe(summary)
    if out_dir is not None:
        out_dir = Path(out_dir)
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / JSON_NAME).write_text(json.dumps(summary, indent=2) + "\n")
        if plot:
            plot_result(result, out_dir / PLOT_NAME, title=estimate.name)
    return summary


# ---- command line -----------------------------------------------------------------------------


def add_eval_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("estimate", type=Path, help="estimated trajectory (TUM or KITTI)")
    parser.add_argument("groundtruth", type=Path, help="ground-truth trajectory (TUM or KITTI)")
    parser.add_argument("--out", type=Path, required=True, help="folder for eval.json and eval.png")
    parser.add_argument("--format", dest="fmt", choices=FORMATS, default="auto", help="trajectory file format")
    parser.add_argument("--times", type=Path, help="KITTI times file (seconds a line), used for both files")
    parser.add_argument("--scan-stamps", type=Path, help="file of scan stamps in seconds (coverage reference)")
    parser.add_argument("--max-time-diff", type=non_negative_float, default=0.01, help="association tolerance [s]")
    parser.add_argument("--nearest", action="store_true", help="nearest-stamp association (no interpolation)")
    align = parser.add_mutually_exclusive_group()
    align.add_argument("--align-scale", action="store_true", help="Sim(3) alignment for the aligned APE")
    align.add_argument(
        "--align-origin",
        action="store_true",
        help="align at the first pose instead of over every pose (evo's --align_origin): the drift from the start",
    )
    parser.add_argument(
        "--kitti-step", type=positive_int, default=1, help="first frame every N frames (KITTI devkit: 10)"
    )
    parser.add_argument("--segments", type=positive_float, nargs="+", help="KITTI segment lengths [m] (default: auto)")
    parser.add_argument("--rpe-delta", type=positive_float, default=1.0, help="evo-style RPE pair distance")
    parser.add_argument("--rpe-unit", choices=RPE_UNITS, default="frames", help="unit of --rpe-delta")
    parser.add_argument("--rpe-all-pairs", action="store_true", help="all pairs instead of consecutive ones")
    parser.add_argument("--no-plot", action="store_true", help="skip eval.png")


def run_eval(args: argparse.Namespace) -> int:
    summary = evaluate_files(
        args.estimate,
        args.groundtruth,
        args.out,
        fmt=args.fmt,
        plot=not args.no_plot,
        estimate_times=args.times,
        scan_stamps=args.scan_stamps,
        max_time_diff_s=args.max_time_diff,
        nearest=args.nearest,
        align_scale=args.align_scale,
        align_origin=args.align_origin,
        kitti_step=args.kitti_step,
        segment_lengths_m=args.segments,
        rpe_delta=args.rpe_delta,
        rpe_unit=args.rpe_unit,
        rpe_all_pairs=args.rpe_all_pairs,
    )
    ape, kitti = summary["ape"], summary["kitti_rpe"]
    print(
        f"associated {summary['associated_poses']}/{summary['estimate_poses']} poses, "
        f"coverage {100 * summary['coverage']:.1f} %"
    )
    print(
        f"APE aligned ({ape['alignment']['method']}) RMSE {ape['translation_m']['rmse']:.4f} m, "
        f"raw {ape['translation_raw_m']['rmse']:.4f} m, rotation {ape['rotation_deg']['rmse']:.3f} deg"
    )
    print(
        f"KITTI RPE {kitti['translation_pct']:.3f} %, {kitti['rotation_deg_per_100m']:.4f} deg/100 m "
        f"({kitti['segment_count']} segments)"
    )
    print(f"RPE RMSE {summary['rpe']['translation_m']['rmse']:.4f} m -> {args.out / JSON_NAME}")
    return 0
