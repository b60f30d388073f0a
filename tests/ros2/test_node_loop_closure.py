"""`farlio ros2` with `loop_closure:=true`: the loop closure's back end on a thread of its own
beside the odometry. On the urban sequence (a drive that revisits nothing) every registered scan
gets a global pose in `map`, equal to its scan odometry (no loop: map -> odom stays the identity),
the keyframes are counted in the diagnostics with no scan dropped from the back end, and the
global map is published in `map`. That the back end closes loops beside the online odometry is
tests/python/test_loop_closure.py's (the racetrack's second lap)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("rclpy")
pytest.importorskip("gtsam")

from farlio._core import NS_PER_S  # noqa: E402
from loopback import Recorder, play, wait_for, wait_for_diagnostics  # noqa: E402

#: the global pose of a scan against its scan odometry when no loop was closed (m)
MAX_DIFFERENCE_M = 1e-6
#: scans the node must register (the rest only dropped as busy on a loaded machine)
MIN_PROCESSED_FRACTION = 0.9
GLOBAL_MAP_TIMEOUT_S = 10.0
#: the sequence drives ~5 m after its standing start: a keyframe a metre
KEYFRAME_DISTANCE_M = 1.0


def _stamp(m) -> int:
    return m.header.stamp.sec * NS_PER_S + m.header.stamp.nanosec


def _position(m) -> np.ndarray:
    p = m.pose.pose.position
    return np.array([p.x, p.y, p.z])


def test_node_publishes_the_global_poses_and_map_beside_the_odometry(urban, ros, start_node):
    path, ds = urban
    recorder = Recorder(ros, extra=("global_odometry", "global_map"))
    try:
        node = start_node(
            f"calib_file:={path / 'calib.yaml'}",
            "loop_closure:=true",
            "global_map_period_s:=0.5",
            f"loop.keyframe_distance_m:={KEYFRAME_DISTANCE_M}",
        )
        recorder.wait_for_node(node)
        played = play(path)
        n = len(ds)
        wait_for_diagnostics(recorder, n, node, played)
        wait_for(lambda: recorder.count("global_map") > 0, GLOBAL_MAP_TIMEOUT_S, "the global map")
        assert node.stop() == 0
        log = node.text()
        assert "Traceback" not in log and "loop closure in map" in log, log

        diags = recorder.diagnostics()
        processed = [d for d in diags if d["processed"] == "True"]
        assert len(processed) >= MIN_PROCESSED_FRACTION * n
        last = diags[-1]
        assert int(last["loop_keyframes"]) >= 3, last
        assert last["loop_loops_accepted"] == "0" and last["loop_scans_dropped"] == "0", last

        scans = {_stamp(m): _position(m) for _, m in recorder.msgs["scan_odometry"]}
        glob = recorder.msgs["global_odometry"]
        assert len(glob) >= len(processed) - 1
        assert all(m.header.frame_id == "map" for _, m in glob)
        differences = [np.linalg.norm(_position(m) - scans[_stamp(m)]) for _, m in glob]
        assert max(differences) < MAX_DIFFERENCE_M, max(differences)
        _, cloud = recorder.msgs["global_map"][-1]
        assert cloud.header.frame_id == "map" and cloud.width > 1000
    finally:
        recorder.close()
