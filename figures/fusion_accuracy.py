#!/usr/bin/env python3
"""Where does the fusion lose accuracy? Runs the deterministic replay on generated sequences with one
fusion part changed at a time and prints, per variant, the accuracy of the registered scan poses
against the exact ground truth, next to LiDAR-only on the same data: docs/fusion.md, "IMU biases, the
registration's covariance, the kernel with the fusion's guess" (its Figures table's racetrack row,
the covariance scale, rot|line), and CHANGELOG.md, "Diagnosis".

Each variant isolates one part of the fusion:
  lidar_only      no fusion (the reference the LIO must not be worse than)
  lio             the defaults
  paper_filter    the paper's filter: no bias states, the fixed LiDAR noise (the other
                  variants run on it with --set fusion.bias.estimate=false
                  fusion.lidar_information_from_registration=false)
  ideal_imu       the same scans, the IMU of the noise-free generator (no noise, no bias)
  ideal_gyro      ideal gyro, noisy accelerometer
  ideal_accel     noisy gyro, ideal accelerometer
  no_ref_angles   fusion.reference_angles.enabled=false
  no_delay_comp   fusion.delay.compensation=false
  no_spread       fusion.delay.spread_steps=1 (each LiDAR result in one update)
  no_bias         fusion.standstill.gyro_bias=false
  fixed_noise     the LiDAR measurement from the fixed fusion.lidar_*_std values instead of the
                  registration's information matrix
First, per seed, the spreads of the ground-truth positions along their principal axes (m). Columns:
APE (m), rotation RMSE (deg) and KITTI-style RPE (%) of the scan poses (body frame); the rotation
RMSE again with the rotation about the trajectory's principal axis taken from the orientations
("rot|line": a 30 s urban drive is a near-line whose positions fix that rotation only to about their
residual over the lateral spread; docs/fusion.md); "align", the angle of the evaluation's alignment
(deg: how far the run's frame is from the ground truth's, as the alignment found it); the end drift
with the first pose aligned (m), the median rotation error of the initial guess the fusion gave the
registration (deg; "-" without fusion) and the rotation RMSE of the 100 Hz fused odometry (deg).

  python figures/fusion_accuracy.py --profile racetrack --duration 30 --seeds 1 2 \
      [--variants lio lidar_only ...] [--set name=value ...]
  python figures/fusion_accuracy.py --profile urban --duration 10 --seeds 1 --covariance-scale
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import tempfile
from pathlib import Path

import farlio  # noqa: F401  (loads the extension)
import numpy as np
from farlio import _core
from farlio.evaluation import make_options
from harness import fixed_latency, generated_sequence

#: rot|line: positions must spread this many RMS residuals across an axis to fix the rotation about
#: it (eval's min_spread_to_residual, default 3); only the principal axis of a drive passes
LINE_MIN_SPREAD_TO_RESIDUAL = 1000.0

# the paper's filter: no bias states, the fixed LiDAR noise
PAPER_FILTER = {"fusion.bias.estimate": "false", "fusion.lidar_information_from_registration": "false"}
VARIANTS: dict[str, tuple[dict[str, str], str]] = {
    # name: (config overrides, IMU source)
    "lidar_only": ({"fusion.enabled": "false"}, "noisy"),
    "lio": ({}, "noisy"),
    "paper_filter": (PAPER_FILTER, "noisy"),
    "ideal_imu": ({}, "ideal"),
    "ideal_gyro": ({}, "ideal_gyro"),
    "ideal_accel": ({}, "ideal_accel"),
    "no_ref_angles": ({"fusion.reference_angles.enabled": "false"}, "noisy"),
    "no_delay_comp": ({"fusion.delay.compensation": "false"}, "noisy"),
    "no_spread": ({"fusion.delay.spread_steps": "1"}, "noisy"),
    "no_bias": ({"fusion.standstill.gyro_bias": "false"}, "noisy"),
    "tight_lidar": ({"fusion.lidar_roll_pitch_std_rad": "0.002", "fusion.lidar_yaw_std_rad": "0.002"}, "noisy"),
    "tight_convergence": ({"registration.convergence_norm": "0.001"}, "noisy"),
    "fixed_noise": ({"fusion.lidar_information_from_registration": "false"}, "noisy"),
}


def rotation_angle_deg(a, b) -> float:
    """Angle of the rotation between two SE3 poses (deg)."""
    return math.degrees((a.inverse() * b).angle_rad())


def mixed_imu(noisy: list, ideal: list, source: str) -> list:
    """The IMU of a variant: noisy, ideal, or one sensor ideal and the other noisy."""
    if source == "noisy":
        return noisy
    if source == "ideal":
        return ideal
    out = []
    for n, i in zip(noisy, ideal, strict=True):
        s = _core.ImuSample()
        s.stamp_ns = n.stamp_ns
        s.gyro_rad_s = (i if source == "ideal_gyro" else n).gyro_rad_s
        s.accel_m_s2 = (i if source == "ideal_accel" else n).accel_m_s2
        out.append(s)
    return out


def poses(trajectory) -> list:
    return [trajectory[i][1] for i in range(len(trajectory))]


class Sequence:
    """A generated sequence (written once to a cache folder and read back): scans, the noisy and
    the ideal IMU, ground truth."""

    def __init__(self, profile: str, seed: int, duration_s: float, cache: Path):
        folder = generated_sequence(cache, profile, seed, duration_s)
        cfg = _core.sim.default_config(profile)
        cfg.seed, cfg.duration_s, cfg.noise_free = seed, duration_s, True
        self.ideal_imu = _core.sim.SequenceGenerator(cfg).imu()
        reader = _core.io.SequenceReader(folder)
        self.imu = reader.imu()
        calib = reader.calibration()
        self.T_imu_lidar = calib.T_imu_lidar
        self.gravity_m_s2 = calib.gravity_m_s2
        self.scans = [reader.read_scan(i) for i in range(reader.num_scans())]
        self.gt_scans = reader.groundtruth_scans()
        self.gt_body = reader.groundtruth()


def run_variant(seq: Sequence, overrides: dict[str, str], imu_source: str) -> dict[str, float]:
    config = _core.Config()
    for name, value in overrides.items():
        config.set(name, value)
    imu = mixed_imu(seq.imu, seq.ideal_imu, imu_source) if config.get("fusion.enabled") else []
    odo = _core.Odometry(config, seq.T_imu_lidar, seq.gravity_m_s2, imu, fixed_latency())
    T_lidar_imu = seq.T_imu_lidar.inverse()
    scans, odometry = _core.Trajectory(), _core.Trajectory()
    guess_errors = []
    to_gt = None  # odometry world -> generator world, from the first scan
    for scan, gt_scan in zip(seq.scans, poses(seq.gt_scans), strict=True):
        fr = odo.process(scan)
        for stamp, pose in odo.take_odometry():
            odometry.push_back(stamp, pose)
        if not fr.processed:
            continue
        scans.push_back(scan.end_stamp_ns, fr.body_pose)
        if to_gt is None:
            to_gt = gt_scan * fr.body_pose.inverse()
        if fr.guess_from_fusion:
            guess_errors.append(rotation_angle_deg(to_gt * fr.scan.initial_guess * T_lidar_imu, gt_scan))
    odo.finish(seq.scans[-1].end_stamp_ns)
    for stamp, pose in odo.take_odometry():
        odometry.push_back(stamp, pose)
    options = make_options()
    r = _core.eval.evaluate(scans, seq.gt_scans, options)
    first = poses(seq.gt_scans)[0] * poses(scans)[0].inverse()  # first pose aligned
    end_drift = np.linalg.norm((first * poses(scans)[-1]).translation - poses(seq.gt_scans)[-1].translation)
    line_options = make_options()
    line_options.min_spread_to_residual = LINE_MIN_SPREAD_TO_RESIDUAL
    r_line = _core.eval.evaluate(scans, seq.gt_scans, line_options)
    row = {
        "ape_m": r.ape.translation_m.rmse,
        "rot_deg": r.ape.rotation_deg.rmse,
        "rot_line_deg": r_line.ape.rotation_deg.rmse,
        "align_deg": math.degrees(r.ape.alignment.transform.angle_rad()),
        "rpe_pct": r.kitti_rpe.translation_pct,
        "end_drift_m": float(end_drift),
        "guess_rot_deg": statistics.median(guess_errors) if guess_errors else math.nan,
        "odom_rot_deg": math.nan,
    }
    if len(odometry) > 1:
        row["odom_rot_deg"] = _core.eval.evaluate(odometry, seq.gt_body, options).ape.rotation_deg.rmse
    return row


def position_spreads_m(trajectory) -> np.ndarray:
    """The spreads of a trajectory's positions along their principal axes (m, largest first: the
    RMS distance from the centroid along each axis), which fix the alignment's rotations about the
    other axes."""
    p = np.array([pose.translation for pose in poses(trajectory)])
    return np.linalg.svd(p - p.mean(axis=0), compute_uv=False) / math.sqrt(len(p))


def covariance_scale(seq: Sequence) -> tuple[float, float]:
    """registration.covariance_scale as measured by the data (LiDAR-only): the mean and median over
    consecutive scans of e^T (H_k^-1 + H_k-1^-1)^-1 e / 6, e the error of the registered relative
    pose against the truth (sensor frame, [t; r])."""
    config = _core.Config()
    config.set("fusion.enabled", "false")
    odo = _core.Odometry(config, seq.T_imu_lidar, seq.gravity_m_s2, [], fixed_latency())
    truth = [p * seq.T_imu_lidar for p in poses(seq.gt_scans)]
    previous, nees = None, []
    for scan, true_pose in zip(seq.scans, truth, strict=True):
        fr = odo.process(scan)
        if not (fr.processed and fr.scan.registered):
            previous = None
            continue
        H = np.asarray(fr.scan.hessian)
        if previous is not None:
            H_prev, pose_prev, true_prev = previous
            e = np.asarray(((true_prev.inverse() * true_pose).inverse() * (pose_prev.inverse() * fr.scan.pose)).log())
            nees.append(e @ np.linalg.solve(np.linalg.inv(H) + np.linalg.inv(H_prev), e) / 6.0)
        previous = (H, fr.scan.pose, true_pose)
    return float(np.mean(nees)), float(np.median(nees))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--profile", default="racetrack", help="generator profile")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2], help="noise seeds")
    p.add_argument("--duration", type=float, default=30.0, help="sequence length (s)")
    p.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS), help="what to run")
    p.add_argument(
        "--cache", type=Path, default=Path(tempfile.gettempdir()) / "farlio_diagnose", help="generated sequences"
    )
    p.add_argument(
        "--covariance-scale",
        action="store_true",
        help="instead of the variants: measure registration.covariance_scale (LiDAR-only relative-pose NEES)",
    )
    p.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE", help="config fields for every variant")
    args = p.parse_args()
    common = dict(item.split("=", 1) for item in args.set)
    if args.covariance_scale:
        for seed in args.seeds:
            mean, median = covariance_scale(Sequence(args.profile, seed, args.duration, args.cache))
            print(f"{args.profile} seed {seed}: covariance_scale mean {mean:.2e}, median {median:.2e}")
        return 0
    print(
        f"{'seed':>4} {'variant':<14} {'APE m':>8} {'rot deg':>8} {'RPE %':>7} {'rot|line':>8} {'align':>6} "
        f"{'drift m':>8} {'guess deg':>9} {'odom deg':>8}"
    )
    for seed in args.seeds:
        seq = Sequence(args.profile, seed, args.duration, args.cache)
        spread = position_spreads_m(seq.gt_scans)
        print(f"{seed:>4} ground-truth positions spread {spread[0]:.2f} / {spread[1]:.2f} / {spread[2]:.2f} m")
        for name in args.variants:
            overrides, imu_source = VARIANTS[name]
            r = run_variant(seq, {**common, **overrides}, imu_source)
            print(
                f"{seed:>4} {name:<14} {r['ape_m']:8.3f} {r['rot_deg']:8.3f} {r['rpe_pct']:7.3f} "
                f"{r['rot_line_deg']:8.3f} {r['align_deg']:6.3f} {r['end_drift_m']:8.2f} {r['guess_rot_deg']:9.3f} "
                f"{r['odom_rot_deg']:8.3f}",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
