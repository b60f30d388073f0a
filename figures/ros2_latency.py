#!/usr/bin/env python3
"""Benchmark of the ROS 2 node over loopback (not a test): a generated urban sequence (~118k-point
clouds, 10 Hz, IMU 100 Hz) published in real time into `farlio ros2`, and per scan:

  node      the node's own time: cloud callback entered -> scan odometry published (diagnostics)
  pipeline  the scan pipeline's frame time (diagnostics pipeline_ms)
  overhead  node - pipeline: decoding, merging, hand-over, waking the result thread, messages
  e2e scan  cloud published -> scan odometry received (adds the DDS transport both ways)
  e2e fused cloud published -> first fused /farlio/odometry received after the scan odometry

median and p99 of each; clouds lost (published vs received by the node); the node's CPU time next
to the CPU time of the same scans through farlio.OnlineOdometry alone (in this process, one after
the other), as a share of one core over the run.

Run with .venv-ros: .venv-ros/bin/python figures/ros2_latency.py [--scans 100] [--input-qos best_effort]
[--transport ros-default] [--json out.json]. Results: docs/ros2.md, "Latency and CPU".
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

MS = 1e-6  # ns -> ms
CLK_TCK = os.sysconf("SC_CLK_TCK")
START_TIMEOUT_S, SETTLE_S = 30.0, 2.0
PERCENTILES = (50, 99)


def cpu_s(pid: int) -> float:
    """User + system CPU time of a process (all its threads)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def pipeline_cpu_s(ds, scans: int, config) -> float:
    """CPU time of the same scans and IMU through OnlineOdometry alone (lockstep, this process)."""
    import farlio

    odo = farlio.OnlineOdometry(config, ds.T_imu_lidar(), ds.gravity_m_s2(), True)
    imu, k = ds.imu(), 0
    loaded = [ds.scan(i) for i in range(scans)]
    start = time.process_time()
    for s in loaded:
        while k < len(imu) and imu[k].stamp_ns <= s.end_stamp_ns:
            odo.add_imu(imu[k])
            k += 1
        odo.add_scan(s)
        odo.wait_idle()
        odo.take_odometry()
        odo.take_frames()
    odo.stop()
    return time.process_time() - start


def farlio_fields() -> set[str]:
    import farlio

    return {name for name, *_ in farlio.Config.fields()}


def stats(values_ms: list[float]) -> str:
    if not values_ms:
        return "n/a"
    p = np.percentile(values_ms, PERCENTILES)
    return f"{p[0]:7.2f} {p[1]:7.2f}"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scans", type=int, default=100)
    ap.add_argument("--input-qos", default="reliable", choices=["reliable", "best_effort"])
    ap.add_argument("--transport", default="large-data", choices=["large-data", "ros-default"])
    ap.add_argument("--param", action="append", default=[], metavar="NAME:=VALUE", help="a node parameter (repeatable)")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args()

    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from farlio.ros2 import choose_transport

    transport = choose_transport(args.transport)  # this process and (inherited) the node
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from farlio.datasets import open_dataset
    from farlio.ros2.conversions import stamp_ns
    from farlio.ros2.play import Player, PlayOptions
    from farlio.simulation import generate
    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    tmp = Path(tempfile.mkdtemp(prefix="farlio_bench_ros2_"))
    seq = tmp / "urban"
    generate("urban", seq, duration_s=args.scans / 10 + 0.5)
    ds = open_dataset(seq)
    from farlio.config import load_config

    config_overrides = [p.replace(":=", "=", 1) for p in args.param if p.split(":=")[0] in farlio_fields()]
    base_cpu = pipeline_cpu_s(ds, args.scans, load_config(None, config_overrides))

    cmd = [sys.executable, "-m", "farlio.cli", "ros2", "--transport", args.transport, "--ros-args"]
    cmd += ["-p", f"calib_file:={seq / 'calib.yaml'}", "-p", f"input_qos:={args.input_qos}"]
    cmd += [a for p in args.param for a in ("-p", p)]
    log = open(tmp / "node.log", "w")  # noqa: SIM115
    node_proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)

    rclpy.init()
    node = rclpy.create_node("farlio_bench")
    got: dict[str, list[tuple[int, object]]] = {"odometry": [], "scan_odometry": [], "diagnostics": []}
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    subs = []
    for key, kind in (("odometry", Odometry), ("scan_odometry", Odometry), ("diagnostics", DiagnosticArray)):
        subs.append(
            node.create_subscription(
                kind, f"/farlio/{key}", lambda m, k=key: got[k].append((time.monotonic_ns(), m)), qos
            )
        )
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    deadline = time.monotonic() + START_TIMEOUT_S
    while not all(s.get_publisher_count() for s in subs):
        if time.monotonic() > deadline or node_proc.poll() is not None:
            print(Path(tmp / "node.log").read_text())
            return 1
        time.sleep(0.05)

    player = Player(node, ds, PlayOptions(max_scans=args.scans, wait_subscribers_s=START_TIMEOUT_S))
    player.wait_for_subscribers()
    cpu0 = cpu_s(node_proc.pid)
    played = player.play()
    time.sleep(SETTLE_S)
    cpu1 = cpu_s(node_proc.pid)
    node_proc.send_signal(signal.SIGINT)
    node_proc.wait(30)
    executor.shutdown()

    diags = [{kv.key: kv.value for kv in m.status[0].values} for _, m in got["diagnostics"]]
    received = int(diags[-1]["clouds"]) if diags else 0
    processed = [d for d in diags[1:] if d["processed"] == "True"]  # the first scan starts the map
    node_ms = [float(d["latency_ms"]) for d in processed]
    pipe_ms = [float(d["pipeline_ms"]) for d in processed]
    over_ms = [a - b for a, b in zip(node_ms, pipe_ms)]
    scan_rx = {stamp_ns(m.header.stamp): t for t, m in got["scan_odometry"]}
    odo_rx = np.array([t for t, _ in got["odometry"]])
    e2e_scan, e2e_fused = [], []
    for stamp, sent in played.sent_ns.items():
        if stamp in scan_rx:
            e2e_scan.append((scan_rx[stamp] - sent) * MS)
            after = odo_rx[odo_rx > scan_rx[stamp]]
            if after.size:
                e2e_fused.append((after[0] - sent) * MS)
    wall_s = played.wall_s + SETTLE_S
    result = {
        "scans_published": played.scans,
        "clouds_received": received,
        "clouds_lost": played.clouds - received,
        "scans_dropped_busy": int(diags[-1]["scans_dropped_busy"]) if diags else None,
        "points_per_scan": float(np.mean([int(d["input_points"]) for d in processed])) if processed else 0,
        "input_qos": args.input_qos,
        "transport": transport,
        "node_cpu_core_share": (cpu1 - cpu0) / wall_s,
        "pipeline_cpu_core_share": base_cpu / wall_s,
        "latency_ms": {
            k: dict(zip(("median", "p99"), np.percentile(v, PERCENTILES).tolist())) if v else None
            for k, v in (
                ("node", node_ms),
                ("pipeline", pipe_ms),
                ("overhead", over_ms),
                ("e2e_scan", e2e_scan),
                ("e2e_fused", e2e_fused),
            )
        },
    }
    print(f"transport: {transport}; input QoS {args.input_qos}")
    print(
        f"clouds: {played.clouds} published, {received} received by the node ({played.clouds - received} lost), "
        f"{result['scans_dropped_busy']} dropped while the pipeline was busy; "
        f"{result['points_per_scan']:.0f} points a scan"
    )
    print("latency (ms)        median     p99")
    for name, values in (
        ("node (arrival->scan odometry)", node_ms),
        ("pipeline frame", pipe_ms),
        ("node overhead", over_ms),
        ("e2e cloud->scan odometry", e2e_scan),
        ("e2e cloud->fused odometry", e2e_fused),
    ):
        print(f"  {name:30s} {stats(values)}")
    print(
        f"CPU (share of one core over {wall_s:.1f} s): node {result['node_cpu_core_share']:.2f}, "
        f"OnlineOdometry alone on the same data {result['pipeline_cpu_core_share']:.2f}"
    )
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
