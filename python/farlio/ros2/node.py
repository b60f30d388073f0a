"""The ROS 2 node `farlio`: live topics into farlio.OnlineOdometry (through live.LiveOdometry), the
odometry out. Topics, parameters and frames: docs/ros2.md.

Threads: the executor thread runs the subscriptions (IMU: feed and publish the fused odometry of
every completed 10 ms step; clouds: decode, merge, hand over), the save_map service and a watchdog
timer; a result thread waits for the scans' results (without the GIL) and publishes the scan
odometry, the registered cloud, the diagnostics and, at a low rate, the local map.
"""

from __future__ import annotations

import signal
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from sensor_msgs.msg import Imu, PointCloud2
from std_srvs.srv import Trigger

import farlio
from farlio import _core

from ..datasets.calib import CalibFile
from . import conversions as conv
from . import retain_freed_memory
from .live import FrameReport, LiveOdometry
from .params import NODE_NAME, NodeParams, config_from, config_param_docs, node_param_docs, node_params_from

if TYPE_CHECKING:
    from farlio.live_loop_closure import LiveLoopClosure

try:  # not on PyPI: present where ROS 2 is installed from its Debian packages
    from tf2_msgs.msg import TFMessage
except ImportError:
    TFMessage = None

#: how often the watchdog assembles waiting scans and looks for silent topics
WATCHDOG_PERIOD_S = 0.05
#: how long the result thread waits for a frame before it looks at its stop flag
RESULT_WAIT_S = 0.1
#: how long the executor waits for work before it looks at the stop flag SIGINT/SIGTERM set
SPIN_TIMEOUT_S = 0.1
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
DEFAULT_GRAVITY_M_S2 = 9.81
MS_PER_S = 1000.0
ODOMETRY_DEPTH, CLOUD_DEPTH, DIAGNOSTICS_DEPTH = 100, 2, 20
MAP_SUFFIXES = {".ply": _core.io.write_ply, ".pcd": _core.io.write_pcd}


def _pose_nis(stats: Any) -> float | str:
    """The pose group's mean NIS per degree of freedom so far ('' before the first, or LiDAR-only)."""
    pose = [g for g in stats.lidar_innovation if g.group == "pose"] if stats is not None else []
    return pose[0].mean_per_dof if pose else ""


class FarlioNode(Node):
    def __init__(self, **kwargs: Any):
        super().__init__(NODE_NAME, **kwargs)
        self.params, self.config = self._declare_and_read()
        extrinsics, gravity = self._calibration()
        self.live = LiveOdometry(
            self.config,
            self.params,
            extrinsics,
            gravity,
            warn=self.get_logger().warning,
            keep_registered_points=self.params.publish_cloud_registered or self.params.loop_closure,
        )
        self.loops = self._loop_closure(extrinsics[0])
        self._loop_error_reported = False
        self._gyro_bias = [0.0, 0.0, 0.0]
        # the odometry messages, filled again for every pose: one for the executor thread (fused
        # odometry), one for the result thread (scan odometry, and the odometry when LiDAR-only)
        self._fused_out = conv.ReusedOdometry(self.params.odom_frame, self.params.base_frame)
        self._scan_out = conv.ReusedOdometry(self.params.odom_frame, self.params.base_frame)
        self._global_out = conv.ReusedOdometry(self.params.map_frame, self.params.base_frame)
        self._map_frames = 0  # processed frames when the local map was last published
        self._last_map_ns = 0
        self._make_publishers()
        self._make_subscriptions()
        self.create_service(Trigger, "~/save_map", self._save_map)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(WATCHDOG_PERIOD_S, self._guarded(self._watchdog), clock=steady)
        self._stopping = threading.Event()
        self._results = threading.Thread(target=self._result_loop, name="farlio-results", daemon=True)
        self._results.start()
        p = self.params
        if self.live.odometry.device_message:
            self.get_logger().warning(self.live.odometry.device_message)
        imu = p.imu_topic if p.uses_imu else "(none)"
        self.get_logger().info(
            f"farlio on {self.live.odometry.device}: IMU {imu}, LiDAR {', '.join(p.lidar_topics)}, "
            f"frames {p.odom_frame} -> {p.base_frame}, time offset {p.time_offset_s} s, "
            f"{'TF on /tf' if self._tf_pub else 'no /tf (tf2_msgs is not installed)'}"
            + (f", loop closure in {p.map_frame}" if self.loops else "")
        )

    def _loop_closure(self, T_imu_lidar: farlio.SE3) -> LiveLoopClosure | None:
        """The loop closure's back end (parameter loop_closure), or None; stops the node at start
        with the extra to install when gtsam is missing."""
        if not self.params.loop_closure:
            return None
        from farlio.live_loop_closure import LiveLoopClosure

        resolution = _core.export_resolution_m(self.config)
        try:
            return LiveLoopClosure(self.config, T_imu_lidar, resolution, self.params.global_map_period_s)
        except ImportError as e:  # an expected error of `farlio ros2`: one line, no traceback
            raise RuntimeError(f"loop_closure: {e}") from None

    # --- parameters and calibration ------------------------------------------------------------
    def _declare_and_read(self) -> tuple[NodeParams, farlio.Config]:
        """Declares every parameter (read only: the odometry is built once) and reads them."""

        def declare(name: str, default: Any, doc: str) -> Any:
            # numbers and lists of numbers: -p x:=1 and x:=1.0 both work
            dynamic = not isinstance(default, str) and not (
                isinstance(default, list) and default and isinstance(default[0], str)
            )
            descriptor = ParameterDescriptor(description=doc, read_only=True, dynamic_typing=dynamic)
            return self.declare_parameter(name, default, descriptor).value

        node_values = {name: declare(name, default, doc) for name, default, doc in node_param_docs()}
        config_values = {name: declare(name, default, doc) for name, default, doc in config_param_docs()}
        return node_params_from(node_values), config_from(config_values)

    def _calibration(self) -> tuple[list[farlio.SE3], float]:
        p = self.params
        if not p.calib_file:
            self.get_logger().warning("no calib_file: identity LiDAR-IMU extrinsic, gravity 9.81 m/s^2")
            return [farlio.SE3() for _ in p.lidar_topics], DEFAULT_GRAVITY_M_S2
        calib = CalibFile(Path(p.calib_file))
        extrinsics = [calib.T_imu_lidar(t, t.lstrip("/")) for t in p.lidar_topics]
        return extrinsics, calib.gravity_m_s2 or DEFAULT_GRAVITY_M_S2

    # --- topics ----------------------------------------------------------------------------------
    def _make_publishers(self) -> None:
        reliable = ReliabilityPolicy.RELIABLE
        self._odom_pub = self.create_publisher(Odometry, "~/odometry", ODOMETRY_DEPTH)
        self._scan_pub = self.create_publisher(Odometry, "~/scan_odometry", ODOMETRY_DEPTH)
        self._cloud_pub = self.create_publisher(PointCloud2, "~/cloud_registered", CLOUD_DEPTH)
        latched = QoSProfile(depth=1, reliability=reliable, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self._map_pub = self.create_publisher(PointCloud2, "~/local_map", latched)
        self._diag_pub = self.create_publisher(DiagnosticArray, "~/diagnostics", DIAGNOSTICS_DEPTH)
        if self.params.loop_closure:
            self._global_pub = self.create_publisher(Odometry, "~/global_odometry", ODOMETRY_DEPTH)
            self._global_map_pub = self.create_publisher(PointCloud2, "~/global_map", latched)
        self._tf_pub = (
            self.create_publisher(TFMessage, "/tf", ODOMETRY_DEPTH)
            if TFMessage is not None and self.params.publish_tf
            else None
        )

    def _make_subscriptions(self) -> None:
        p = self.params
        reliability = ReliabilityPolicy.RELIABLE if p.input_qos == "reliable" else ReliabilityPolicy.BEST_EFFORT
        if p.uses_imu:
            self.create_subscription(
                Imu, p.imu_topic, self._on_imu, QoSProfile(depth=p.imu_queue_depth, reliability=reliability)
            )
        lidar_qos = QoSProfile(depth=p.lidar_queue_depth, reliability=reliability)
        for k, topic in enumerate(p.lidar_topics):
            self.create_subscription(
                PointCloud2, topic, self._guarded(lambda msg, k=k: self.live.add_cloud(k, msg)), lidar_qos
            )

    def _guarded(self, callback: Any) -> Any:
        """The callback, with an exception counted and reported instead of ending the node."""

        def run(*args: Any) -> None:
            try:
                callback(*args)
            except Exception as e:
                self.live.report("callback_errors", f"input dropped: {type(e).__name__}: {e}")

        return run

    def _on_imu(self, msg: Imu) -> None:
        for s in self.live.add_imu(conv.imu_sample(msg)):
            self._publish_odometry(
                self._fused_out, s.stamp_ns, s.body_pose, s.velocity_body_m_s, self._angular_velocity()
            )

    def _angular_velocity(self) -> list[float]:
        return [float(w - b) for w, b in zip(self.live.last_gyro_rad_s, self._gyro_bias)]

    def _publish_odometry(
        self, out: conv.ReusedOdometry, stamp: int, pose: farlio.SE3, velocity: Any = None, angular: Any = None
    ) -> None:
        """Publishes the odometry (and TF) through `out`, the message of the calling thread."""
        if not out.fill(stamp, pose, velocity, angular):
            self.live.report("poses_non_finite", f"non-finite odometry pose at {stamp} ns not published")
            return
        p = self.params
        self._odom_pub.publish(out.msg)
        if self._tf_pub is not None:
            self._tf_pub.publish(TFMessage(transforms=[conv.transform_msg(stamp, pose, p.odom_frame, p.base_frame)]))

    # --- results ---------------------------------------------------------------------------------
    def _result_loop(self) -> None:
        while not self._stopping.is_set():
            try:
                for report in self.live.wait_frames(RESULT_WAIT_S):
                    self._publish_frame(report)
                    self._publish_global(report.frame)
                self._publish_local_map()
                self._publish_global_map()
            except Exception as e:  # a publisher of a context shut down under us: stop quietly
                if not self._stopping.is_set() and rclpy.ok():
                    self.get_logger().error(f"result thread: {type(e).__name__}: {e}")

    def _publish_frame(self, report: FrameReport) -> None:
        f, p = report.frame, self.params
        stamp = f.scan.stamp_ns
        ok = f.processed and self._scan_out.fill(stamp, f.body_pose)
        if f.processed and not ok:
            self.live.report("poses_non_finite", f"non-finite scan pose at {stamp} ns not published")
        if ok:
            self._scan_pub.publish(self._scan_out.msg)
            report.done_ns = time.monotonic_ns()  # the latency ends with the scan odometry out
            if not self.live.odometry.inertial:  # LiDAR-only: the odometry at the scan rate
                self._publish_odometry(self._scan_out, stamp, f.body_pose)
            if p.publish_cloud_registered:
                self._cloud_pub.publish(conv.points_msg(f.registered_points, stamp, p.odom_frame))
        if f.processed and f.scan.lost:
            self.live.report("scans_lost", f"scan at {stamp} ns lost in the prior map: {f.scan.failure}")
        stats = self.live.odometry.fusion_stats
        if stats is not None:
            self._gyro_bias = list(stats.gyro_bias_rad_s)
        self._diag_pub.publish(self._diagnostics(report))

    def _publish_global(self, f: Any) -> None:
        """With loop_closure: hands the registered scan to the back end (after the scan odometry is
        out), then publishes the scan's global pose and map_frame -> odom_frame."""
        if self.loops is None or not f.processed or f.scan.failure or f.scan.lost:
            return
        if self.loops.error and not self._loop_error_reported:
            self._loop_error_reported = True  # the odometry goes on; the correction stays as it was
            self.get_logger().error(f"loop closure stopped: {self.loops.error}")
        self.loops.submit(f.scan.stamp_ns, f.scan.pose.matrix(), f.registered_points)
        stamp, p = f.scan.stamp_ns, self.params
        correction = farlio.SE3.from_matrix(self.loops.map_from_odometry())
        if self._global_out.fill(stamp, correction * f.body_pose):
            self._global_pub.publish(self._global_out.msg)
        if self._tf_pub is not None:
            self._tf_pub.publish(
                TFMessage(transforms=[conv.transform_msg(stamp, correction, p.map_frame, p.odom_frame)])
            )

    def _publish_global_map(self) -> None:
        points = self.loops.take_global_map() if self.loops is not None else None
        if points is not None and len(points):
            self._global_map_pub.publish(conv.points_msg(points, self.live.last_scan_end or 0, self.params.map_frame))

    def _diagnostics(self, report: FrameReport) -> DiagnosticArray:
        f = report.frame
        r = f.scan
        stats = self.live.odometry.fusion_stats
        status = DiagnosticStatus(name="farlio: scan", hardware_id=NODE_NAME)
        status.level = DiagnosticStatus.OK if f.processed and not f.drop_reason else DiagnosticStatus.WARN
        status.message = f.drop_reason or ("registered" if r.registered else "first scan: map started")
        values = {
            "stamp_ns": r.stamp_ns,
            "mode": "lidar-inertial" if self.live.odometry.inertial else "lidar-only",
            "processed": f.processed,
            "fused": f.fused,
            "drop_reason": f.drop_reason,
            "arrival_ns": report.arrival_ns,  # monotonic clock
            "latency_ms": report.latency_s * MS_PER_S,  # cloud arrival -> scan odometry published
            "pipeline_ms": r.timings.total_s * MS_PER_S,
            "iterations": r.iterations,
            "converged": r.converged,
            "inlier_fraction": r.inlier_fraction,
            "lost": r.lost,
            "input_points": r.input_points,
            "kept_points": r.kept_points,
            "map_points": r.map_points,
            "guess_from_fusion": f.guess_from_fusion,
            "scans_dropped_busy": self.live.odometry.scans_dropped_busy,
            # how the filter started (at rest or in motion), '' before
            "fusion_initialization": stats.initialization.mode if stats is not None else "",
            # the LiDAR poses' mean normalised innovation squared per dof so far ('' before the
            # first): 1 when the filter's noise fits the data (docs/fusion.md, "Innovation statistics")
            "fusion_pose_nis_per_dof": _pose_nis(stats),
            **self.live.stats.as_dict(),
        }
        if self.loops is not None:
            values.update({f"loop_{k}": v for k, v in vars(self.loops.stats()).items()})
        status.values = [KeyValue(key=k, value=str(v)) for k, v in values.items()]
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = conv.to_stamp(r.stamp_ns)
        return msg

    def _publish_local_map(self) -> None:
        period_ns = self.params.local_map_period_s * 1e9
        now = time.monotonic_ns()
        frames = self.live.stats.scans
        if period_ns <= 0 or now - self._last_map_ns < period_ns or frames == self._map_frames:
            return
        self._last_map_ns, self._map_frames = now, frames
        points = self.live.odometry.map_points()
        if len(points):
            stamp = self.live.last_scan_end or 0
            self._map_pub.publish(conv.points_msg(points, stamp, self.params.odom_frame))

    # --- service, watchdog, shutdown -----------------------------------------------------------
    def _save_map(self, request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        path = Path(self.params.map_file)
        writer = MAP_SUFFIXES.get(path.suffix.lower())
        if writer is None:
            response.success, response.message = False, f"map_file {path}: expected a .ply or .pcd name"
            return response
        points = self.live.odometry.map_points()
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            writer(path, farlio.Scan(points))
        except (OSError, ValueError) as e:
            response.success, response.message = False, f"{path}: {e}"
            return response
        response.success, response.message = True, f"{len(points)} points written to {path.resolve()}"
        self.get_logger().info(response.message)
        return response

    def _watchdog(self) -> None:
        self.live.poll()
        fell, resumed = self.live.silent_topics()
        for t in fell:
            never = "" if self.live.has_seen(t) else " (none since the start)"
            self.get_logger().warning(f"no message on {t} for {self.params.silent_topic_timeout_s} s{never}")
        for t in resumed:
            self.get_logger().info(f"{t} is publishing again")

    def close(self) -> None:
        """Stops the result thread and the odometry (the scan in progress is finished)."""
        self._stopping.set()
        self._results.join()
        self.live.stop()
        if self.loops is not None:
            try:
                self.loops.stop(drain=False)
            except Exception as e:  # reported, not raised: the node's own shutdown goes on
                print(f"farlio: loop closure had stopped: {type(e).__name__}: {e}", file=sys.stderr)
        counts = {k: v for k, v in self.live.stats.as_dict().items() if v}
        counts["scans_dropped_busy"] = self.live.odometry.scans_dropped_busy
        # printed: the context (and with it /rosout) is gone after SIGINT
        print("farlio stopped: " + ", ".join(f"{k} {v}" for k, v in counts.items()), file=sys.stderr)


def run(ros_args: list[str], transport: str = "") -> int:
    """`farlio ros2 [--ros-args ...]`: runs the node until SIGINT or SIGTERM (or the context shuts
    down); `transport` says which DDS transport settings are in use (for the log).

    The signals only set a flag that the spin loop looks at between callbacks: with rclpy's own
    handler a KeyboardInterrupt could land inside rclpy (once in a loopback run it left a
    half-made Task whose __del__ printed a traceback at exit)."""
    memory_kept = retain_freed_memory()  # before the first cloud's buffers
    rclpy.init(args=[NODE_NAME, *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    stop = threading.Event()
    previous = {s: signal.signal(s, lambda *_: stop.set()) for s in STOP_SIGNALS}
    node = None
    try:
        node = FarlioNode()
        if transport:
            node.get_logger().info(f"transport: {transport}")
        if not memory_kept:
            node.get_logger().info("the allocator is not glibc's: its own policy for freed memory applies")
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stop.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=SPIN_TIMEOUT_S)
    except ExternalShutdownException:
        pass
    finally:
        if node is not None:
            node.close()
            node.destroy_node()
        rclpy.try_shutdown()
        for s, handler in previous.items():
            signal.signal(s, handler)
    return 0


__all__ = ["FarlioNode", "run"]
