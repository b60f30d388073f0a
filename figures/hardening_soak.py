#!/usr/bin/env python3
"""Soak (docs/hardening.md, "Soak: 10 km of racetrack"): the LIO over a long generated run in memory
(default: 10 km of the racetrack, 2.4 laps at up to 70 m/s), with the whole map accumulated as
--save-map does, through the replay of `farlio run` (Odometry, measured latency) or with --online
through OnlineOdometry (its worker thread; IMU pushed up to each scan's end, then the scan, in
lockstep). Every --every-s seconds of data it prints the process's resident memory (VmRSS), the
submap's bytes and points (bounded by map.removal_radius_m), the whole map's cells, those in memory
and their bytes (the tiles the sensor can reach; the others wait on disk, as with --save-map), and
the frame time so far (median, p99). Memory that keeps growing lap after lap is a leak: the
odometry, the submap and the whole map's cells in memory must stay level.

Usage: python figures/hardening_soak.py [--profile racetrack] [--km 10] [--every-s 10] [--seed 1] [--online] [--no-map]
       [--no-spill]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from farlio import _core
from harness import work_folder

MS_PER_S, BYTES_PER_MIB = 1e3, 2**20
#: the racetrack's first lap takes 82.7 s (4.13 km, from rest), then 76.4 s a lap (docs/simulation.md)
RACETRACK_FIRST_LAP = (82.7, 4130.0)
RACETRACK_LAP_S = 76.4


def rss_mib() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def submap_mib(odo, online: bool) -> float:
    """The submap's bytes (the replay reports its backend's; online: its points' bytes)."""
    if online:
        return len(odo.map_points()) * 4 * 4 / BYTES_PER_MIB  # approximate: float xyz + pad per point
    return odo.map_memory_bytes / BYTES_PER_MIB


def duration_for(profile: str, km: float) -> float:
    if profile != "racetrack":
        raise SystemExit("--km is for the racetrack; give --duration for other profiles")
    first_s, first_m = RACETRACK_FIRST_LAP
    return first_s + max(0.0, km * 1000.0 - first_m) / first_m * RACETRACK_LAP_S


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", default="racetrack")
    ap.add_argument("--km", type=float, default=10.0)
    ap.add_argument("--duration", type=float, default=None, help="seconds of data (instead of --km)")
    ap.add_argument("--every-s", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--online", action="store_true", help="OnlineOdometry instead of the replay")
    ap.add_argument("--no-map", action="store_true", help="without the whole map (the odometry's memory alone)")
    ap.add_argument("--no-spill", action="store_true", help="the whole map all in memory (no tiles on disk)")
    args = ap.parse_args()
    cfg = _core.sim.default_config(args.profile)
    cfg.seed = args.seed
    cfg.duration_s = args.duration or duration_for(args.profile, args.km)
    gen = _core.sim.SequenceGenerator(cfg)
    imu = gen.imu()
    config = _core.Config()
    options = _core.ReplayOptions()  # measured latency, as farlio run
    if args.online:
        odo = _core.OnlineOdometry(config, gen.T_imu_lidar(), gen.gravity_m_s2())
    else:
        odo = _core.Odometry(config, gen.T_imu_lidar(), gen.gravity_m_s2(), imu, options)
    # the whole map's tiles wait on disk in a temporary folder, removed at the end
    with work_folder(prefix="farlio-soak-tiles-") as tiles:
        export = None
        frame_ms: list[float] = []
        print(f"{args.profile} seed {args.seed}: {cfg.duration_s:.0f} s of data, {gen.num_scans()} scans, "
              f"{'OnlineOdometry' if args.online else 'replay (Odometry)'}")  # fmt: skip
        print(f"{'t s':>6} {'RSS MiB':>8} {'submap MiB':>10} {'submap pts':>10} {'map cells':>10} {'in memory':>10} "
              f"{'map MiB':>8} {'ms med':>7} {'ms p99':>7} {'wall s':>7}")  # fmt: skip
        start = time.perf_counter()
        next_report = args.every_s
        t0 = None
        k = 0  # next IMU sample (online)
        for i in range(gen.num_scans()):
            scan = gen.scan(i)
            if args.online:
                while k < len(imu) and imu[k].stamp_ns <= scan.end_stamp_ns:
                    odo.add_imu(imu[k])
                    k += 1
                odo.add_scan(scan)
                odo.wait_idle()
                frames = odo.take_frames()
                fr = frames[-1] if frames else None
            else:
                fr = odo.process(scan)
            t0 = scan.end_stamp_ns if t0 is None else t0
            if fr is not None and fr.processed:
                frame_ms.append(fr.scan.timings.total_s * MS_PER_S)
                if export is None and not args.no_map:
                    # online: the configured voxel size (the racetrack keeps the 4 m the auto scaling allows)
                    effective = config if args.online else odo.effective_config
                    spill = "" if args.no_spill else str(tiles)
                    export = _core.MapExport(_core.export_resolution_m(effective), effective, spill)
                if export is not None and not fr.scan.failure:
                    export.add(scan, fr.scan)
            odo.take_odometry()
            t = (scan.end_stamp_ns - t0) / 1e9
            if t >= next_report or i == gen.num_scans() - 1:
                next_report += args.every_s
                last = frame_ms[-int(args.every_s * gen.lidar_rate_hz()) :]
                print(
                    f"{t:6.0f} {rss_mib():8.0f} {submap_mib(odo, args.online):10.1f} {len(odo.map_points()):10d} "
                    f"{export.cells if export else 0:10d} {export.cells_in_memory if export else 0:10d} "
                    f"{export.memory_bytes / BYTES_PER_MIB if export else 0:8.1f} "
                    f"{np.median(last):7.2f} "
                    f"{np.percentile(last, 99):7.2f} {time.perf_counter() - start:7.0f}",
                    flush=True,
                )
        export = None  # the map and its tiles go before their folder


if __name__ == "__main__":
    main()
