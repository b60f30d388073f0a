"""The node's parameters: its own (topics, frames, calibration, time handling, QoS, outputs), each
declared once here with its default and meaning, and every field of `farlio config` under its own
dotted name (e.g. `map.voxel_size_m`). No rclpy here: the node declares and reads them, the default
parameter file (params.yaml) and the docs are generated from the same lists.
"""

from __future__ import annotations

import dataclasses
import textwrap
from dataclasses import dataclass, field
from typing import Any

import yaml

from farlio import Config
from farlio.datasets.pointcloud2 import HEADER_STAMPS, TIME_UNITS, TimeOptions

NODE_NAME = "farlio"
#: columns of the generated parameter file
YAML_WIDTH = 100
#: values of input_qos
INPUT_QOS = ("reliable", "best_effort")


def _param(default: Any, doc: str) -> Any:
    if isinstance(default, list):
        return field(default_factory=lambda: list(default), metadata={"doc": doc})
    return field(default=default, metadata={"doc": doc})


@dataclass
class NodeParams:
    """The node's own parameters (ROS parameter name = attribute name)."""

    imu_topic: str = _param("/imu", "sensor_msgs/Imu input; '' or 'none': LiDAR-only odometry")
    lidar_topics: list[str] = _param(
        ["/points"], "sensor_msgs/PointCloud2 inputs; several are merged into one scan per period of the first"
    )
    calib_file: str = _param(
        "",
        "calib.yaml of the sequence-folder format: T_imu_lidar (4x4, or {topic or frame id: 4x4} for several "
        "LiDARs) and gravity; '': identity extrinsic and 9.81 m/s^2 (with a warning)",
    )
    odom_frame: str = _param("odom", "frame of the odometry (the body pose at the first scan, gravity aligned)")
    base_frame: str = _param("base_link", "child frame of the odometry: the body (IMU) frame of calib_file")
    time_offset_s: float = _param(
        0.0, "LiDAR-IMU time offset: added to every LiDAR stamp to put it on the IMU clock (t_imu = t_lidar + offset)"
    )
    time_field: str = _param(
        "auto", "PointCloud2 per-point time field ('auto': detected as `farlio run` does; 'none': no undistortion)"
    )
    time_unit: str = _param("auto", f"unit of the time field, one of {', '.join(TIME_UNITS)}")
    header_stamp: str = _param(
        "auto", f"whether a cloud's header stamp is its scan start or end: {', '.join(HEADER_STAMPS)}"
    )
    input_qos: str = _param(
        "reliable", f"reliability of the input subscriptions, one of {', '.join(INPUT_QOS)} (reliable: no cloud lost)"
    )
    lidar_queue_depth: int = _param(5, "history depth of the PointCloud2 subscriptions")
    imu_queue_depth: int = _param(200, "history depth of the Imu subscription")
    imu_wait_s: float = _param(
        1.0, "how long clouds wait for a first IMU sample (dropped meanwhile) before the odometry starts LiDAR-only"
    )
    lidar_merge_wait_s: float = _param(
        0.1, "several LiDARs: how long a scan waits for the other LiDARs' points of its period"
    )
    silent_topic_timeout_s: float = _param(1.0, "an input without a message for this long is reported as silent")
    publish_tf: bool = _param(True, "broadcast odom_frame -> base_frame on /tf (needs tf2_msgs)")
    publish_cloud_registered: bool = _param(True, "publish the undistorted, registered scan on cloud_registered")
    local_map_period_s: float = _param(2.0, "period of the local_map publication (transient local); 0: never")
    map_file: str = _param("farlio_map.ply", "where the save_map service writes the submap (.ply or .pcd)")
    prior_map: str = _param(
        "",
        "a map (map.pcd or map.ply of `farlio run --save-map`) to localize in: held fixed, odom_frame is its frame; "
        "a scan matching less than localization.min_inlier_fraction of its points is lost (diagnostics); '': odometry",
    )
    initial_pose: list[float] = _param(
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        "body pose at the first scan in odom_frame (the prior map's frame): X Y Z (m) ROLL PITCH YAW (deg); with an "
        "IMU roll and pitch come from gravity",
    )
    loop_closure: bool = _param(
        False,
        "loop closure on a thread of its own (the back end of `farlio run --loop-closure`, loop.* parameters): "
        "publishes map_frame -> odom_frame on /tf, global_odometry and global_map; needs gtsam (farlio[mapping])",
    )
    map_frame: str = _param("map", "with loop_closure: the global frame (REP 105's map), parent of odom_frame")
    global_map_period_s: float = _param(
        5.0, "with loop_closure: the shortest period of the global_map publication (transient local)"
    )

    def time_options(self) -> TimeOptions:
        return TimeOptions(self.time_field, self.time_unit, self.header_stamp)

    def validate(self) -> None:
        """ValueError naming the parameter that is out of its range."""
        self.time_options()  # checks unit and header stamp
        if self.input_qos not in INPUT_QOS:
            raise ValueError(f"input_qos '{self.input_qos}': expected one of {', '.join(INPUT_QOS)}")
        if not self.lidar_topics or any(not t for t in self.lidar_topics):
            raise ValueError(f"lidar_topics {self.lidar_topics}: expected one or more topic names")
        for name in ("lidar_queue_depth", "imu_queue_depth"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} {getattr(self, name)}: expected at least 1")
        for name in (
            "imu_wait_s",
            "lidar_merge_wait_s",
            "silent_topic_timeout_s",
            "local_map_period_s",
            "global_map_period_s",
        ):
            if not getattr(self, name) >= 0:
                raise ValueError(f"{name} {getattr(self, name)}: expected >= 0")
        if len(self.initial_pose) != 6 or not all(abs(v) < float("inf") for v in self.initial_pose):
            raise ValueError(f"initial_pose {self.initial_pose}: expected X Y Z ROLL PITCH YAW (6 finite numbers)")
        if not abs(self.time_offset_s) < float("inf"):
            raise ValueError(f"time_offset_s {self.time_offset_s}: expected a finite number")

    @property
    def uses_imu(self) -> bool:
        return self.imu_topic not in ("", "none")


def node_param_docs() -> list[tuple[str, Any, str]]:
    """[(name, default, doc)] of the node's own parameters, in declaration order."""
    defaults = NodeParams()
    return [(f.name, getattr(defaults, f.name), f.metadata["doc"]) for f in dataclasses.fields(NodeParams)]


def config_param_docs() -> list[tuple[str, Any, str]]:
    """[(dotted name, default, doc with its valid range)] of every config field."""
    return [(name, default, f"{doc} ({valid})" if valid else doc) for name, default, doc, valid in Config.fields()]


def node_params_from(values: dict[str, Any]) -> NodeParams:
    """NodeParams from {name: value} (missing names keep their defaults); numbers are converted to
    the parameter's type, so that `-p time_offset_s:=0` (an integer) is accepted."""
    params = NodeParams()
    for f in dataclasses.fields(NodeParams):
        if f.name not in values:
            continue
        value = values[f.name]
        kind = type(getattr(params, f.name))
        if kind is float and isinstance(value, (int, float)) and not isinstance(value, bool):
            value = float(value)
        elif kind is list:  # of the default's element type (names, or numbers given as integers too)
            element = type(getattr(params, f.name)[0]) if getattr(params, f.name) else str
            try:
                value = [element(v) for v in value]
            except (TypeError, ValueError):
                raise ValueError(f"parameter {f.name}: expected a list of {element.__name__}, got {value!r}") from None
        elif not isinstance(value, kind):
            raise ValueError(f"parameter {f.name}: expected a {kind.__name__}, got {value!r}")
        setattr(params, f.name, value)
    params.validate()
    return params


def config_from(values: dict[str, Any]) -> Config:
    """The pipeline config from {dotted name: value}; ValueError naming a field out of its range."""
    cfg = Config()
    for name, value in values.items():
        cfg.set(name, value)
    cfg.validate()
    return cfg


def default_params_yaml() -> str:
    """The default parameter file (ros__parameters of the node `farlio`), every parameter with
    its meaning as a comment: the shipped params.yaml is this text."""
    lines = [
        "# farlio ROS 2 node: every parameter with its default (generated by farlio.ros2.params).",
        "# Use: farlio ros2 --ros-args --params-file params.yaml",
        f"{NODE_NAME}:",
        "  ros__parameters:",
        "    # --- the node ---",
    ]

    def entry(name: str, value: Any, doc: str) -> None:
        lines.extend(textwrap.wrap(doc, YAML_WIDTH, initial_indent="    # ", subsequent_indent="    #   "))
        text = yaml.safe_dump({name: value}, default_flow_style=True, width=1000).strip()
        lines.append(f"    {text[1:-1] if text.startswith('{') else text}")

    for name, value, doc in node_param_docs():
        entry(name, value, doc)
    lines.append("    # --- the odometry (farlio config) ---")
    for name, value, doc in config_param_docs():
        entry(name, value, doc)
    return "\n".join(lines) + "\n"
