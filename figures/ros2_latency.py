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
[--transport ros-default] [--param NAME:=VALUE ...] [--profile P --lidar L --lidar-rate HZ]
[--json out.json]. Results: docs/ros2.md, "Latency and CPU".
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
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


def parse_args() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scans", type=int, default=100)
    ap.add_argument("--input-qos", default="reliable", choices=["reliable", "best_effort"])
    ap.add_argument("--transport", default="large-data", choices=["large-data", "ros-default"])
    ap.add_argument("--param", action="append", default=[], metavar="NAME:=VALUE", help="a node parameter (repeatable)")
    ap.add_argument("--profile", default="urban", help="the generated sequence's profile")
    ap.add_argument("--lidar", default="profile", help="the simulator's LiDAR model (farlio simulate --lidar)")
    ap.add_argument("--lidar-rate", type=float, default=10.0, help="LiDAR rate (Hz)")
    ap.add_argument("--json", type=Path, default=None)
    return ap.parse_args()


def start_node(args: argparse.Namespace, seq: Path, log_path: Path) -> subprocess.Popen:
    """`farlio ros2` in its own process, with the sequence's calibration and the given parameters."""
    cmd = [sys.executable, "-m", "farlio.cli", "ros2", "--transport", args.transport, "--ros-args"]
    cmd += ["-p", f"calib_file:={seq / 'calib.yaml'}", "-p", f"input_qos:={args.input_qos}"]
    cmd += [a for p in args.param for a in ("-p", p)]
    log = open(log_path, "w")  # noqa: SIM115
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)


def subscribe(node, got: dict[str, list[tuple[int, object]]]) -> list:
    """Subscriptions to the node's odometry, scan odometry and diagnostics, stamped on arrival."""
    from diagnostic_msgs.msg import DiagnosticArray
    from nav_msgs.msg import Odometry
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    return [
        node.create_subscription(kind, f"/farlio/{key}", lambda m, k=key: got[k].append((time.monotonic_ns(), m)), qos)
        for key, kind in (("odometry", Odometry), ("scan_odometry", Odometry), ("diagnostics", DiagnosticArray))
    ]


def wait_for_publishers(subs: list, node_proc: subprocess.Popen) -> bool:
    deadline = time.monotonic() + START_TIMEOUT_S
    while not all(s.get_publisher_count() for s in subs):
        if time.monotonic() > deadline or node_proc.poll() is not None:
            return False
        time.sleep(0.05)
    return True


def latencies(got: dict[str, list[tuple[int, object]]], sent_ns: dict[int, int]) -> dict[str, list[float]]:
    """Per processed scan (ms): the node's latency, the pipeline's, their difference, and end to end
    from publishing the cloud to the scan odometry and to the next fused odometry."""
    from farlio.ros2.conversions import stamp_ns

    diags = [{kv.key: kv.value for kv in m.status[0].values} for _, m in got["diagnostics"]]
    processed = [d for d in diags[1:] if d["processed"] == "True"]  # the first scan starts the map
    node_ms = [float(d["latency_ms"]) for d in processed]
    pipe_ms = [float(d["pipeline_ms"]) for d in processed]
    scan_rx = {stamp_ns(m.header.stamp): t for t, m in got["scan_odometry"]}
    odo_rx = np.array([t for t, _ in got["odometry"]])
    e2e_scan, e2e_fused = [], []
    for stamp, sent in sent_ns.items():
        if stamp in scan_rx:
            e2e_scan.append((scan_rx[stamp] - sent) * MS)
            after = odo_rx[odo_rx > scan_rx[stamp]]
            if after.size:
                e2e_fused.append((after[0] - sent) * MS)
    over_ms = [a - b for a, b in zip(node_ms, pipe_ms)]
    return {"node": node_ms, "pipeline": pipe_ms, "overhead": over_ms, "e2e_scan": e2e_scan, "e2e_fused": e2e_fused}


def summarise(got, played, lat: dict[str, list[float]], args, transport: str, cpu: float, base_cpu: float) -> dict:
    diags = [{kv.key: kv.value for kv in m.status[0].values} for _, m in got["diagnostics"]]
    processed = [d for d in diags[1:] if d["processed"] == "True"]
    received = int(diags[-1]["clouds"]) if diags else 0
    wall_s = played.wall_s + SETTLE_S
    return {
        "scans_published": played.scans,
        "clouds_received": received,
        "clouds_lost": played.clouds - received,
        "scans_dropped_busy": int(diags[-1]["scans_dropped_busy"]) if diags else None,
        "points_per_scan": float(np.mean([int(d["input_points"]) for d in processed])) if processed else 0,
        "input_qos": args.input_qos,
        "transport": transport,
        "wall_s": wall_s,
        "node_cpu_core_share": cpu / wall_s,
        "pipeline_cpu_core_share": base_cpu / wall_s,
        # with loop_closure: the back end's counters at the last scan (keyframes, loops, backlog)
        "loop_closure": {k[len("loop_") :]: int(v) for k, v in diags[-1].items() if k.startswith("loop_")}
        if diags
        else {},
        "latency_ms": {
            k: dict(zip(("median", "p99"), np.percentile(v, PERCENTILES).tolist())) if v else None
            for k, v in lat.items()
        },
    }


def print_report(result: dict, played, lat: dict[str, list[float]]) -> None:
    received = result["clouds_received"]
    print(f"transport: {result['transport']}; input QoS {result['input_qos']}")
    print(
        f"clouds: {played.clouds} published, {received} received by the node ({played.clouds - received} lost), "
        f"{result['scans_dropped_busy']} dropped while the pipeline was busy; "
        f"{result['points_per_scan']:.0f} points a scan"
    )
    print("latency (ms)        median     p99")
    for name, key in (
        ("node (arrival->scan odometry)", "node"),
        ("pipeline frame", "pipeline"),
        ("node overhead", "overhead"),
        ("e2e cloud->scan odometry", "e2e_scan"),
        ("e2e cloud->fused odometry", "e2e_fused"),
    ):
        print(f"  {name:30s} {stats(lat[key])}")
    if result["loop_closure"]:
        print("loop closure at the last scan: " + ", ".join(f"{k} {v}" for k, v in result["loop_closure"].items()))
    print(
        f"CPU (share of one core over {result['wall_s']:.1f} s): node {result['node_cpu_core_share']:.2f}, "
        f"OnlineOdometry alone on the same data {result['pipeline_cpu_core_share']:.2f}"
    )


def main() -> int:
    args = parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="farlio_bench_ros2_"))
    try:
        return measure(args, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def measure(args: argparse.Namespace, tmp: Path) -> int:
    """Generates the sequence into `tmp`, starts the node, plays the scans to it and reports."""
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from farlio.ros2 import choose_transport

    transport = choose_transport(args.transport)  # this process and (inherited) the node
    import rclpy
    from farlio.config import load_config
    from farlio.datasets import open_dataset
    from farlio.ros2.play import Player, PlayOptions
    from farlio.simulation import generate
    from rclpy.executors import SingleThreadedExecutor

    seq = tmp / args.profile
    generate(
        args.profile,
        seq,
        duration_s=args.scans / args.lidar_rate + 0.5,
        lidar=args.lidar,
        lidar_rate_hz=args.lidar_rate,
    )
    ds = open_dataset(seq)
    config_overrides = [p.replace(":=", "=", 1) for p in args.param if p.split(":=")[0] in farlio_fields()]
    base_cpu = pipeline_cpu_s(ds, args.scans, load_config(None, config_overrides))
    node_proc = start_node(args, seq, tmp / "node.log")

    rclpy.init()
    node = rclpy.create_node("farlio_bench")
    got: dict[str, list[tuple[int, object]]] = {"odometry": [], "scan_odometry": [], "diagnostics": []}
    subs = subscribe(node, got)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    if not wait_for_publishers(subs, node_proc):
        print((tmp / "node.log").read_text())
        return 1

    player = Player(node, ds, PlayOptions(max_scans=args.scans, wait_subscribers_s=START_TIMEOUT_S))
    player.wait_for_subscribers()
    cpu0 = cpu_s(node_proc.pid)
    played = player.play()
    time.sleep(SETTLE_S)
    cpu1 = cpu_s(node_proc.pid)
    node_proc.send_signal(signal.SIGINT)
    node_proc.wait(30)
    executor.shutdown()

    lat = latencies(got, played.sent_ns)
    result = summarise(got, played, lat, args, transport, cpu1 - cpu0, base_cpu)
    print_report(result, played, lat)
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
