"""Fixtures of the ROS 2 loopback tests (run with .venv-ros/bin/python -m pytest tests/ros2): the
node and the player run as subprocesses (`farlio ros2`, `farlio ros2-play`), a recorder node in the
test process subscribes to the node's outputs (loopback.py). Discovery stays on this machine
(ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST) in a ROS domain of its own, drawn per test run.

Every test module skips when rclpy cannot be imported (the ROS 2 wheels are missing)."""

from __future__ import annotations

import os
import random
from pathlib import Path

import pytest

#: ROS domains 1..100 keep the ports of every participant below 32768 on Linux
os.environ["ROS_DOMAIN_ID"] = str(random.randint(1, 100))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_STATIC_PEERS", None)
for _name in ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE"):
    os.environ.pop(_name, None)


from loopback import SEQUENCE_S, NodeProcess, Recorder  # noqa: E402


@pytest.fixture(scope="session")
def ros():
    """rclpy for the recorder (one context for the session)."""
    import rclpy
    from farlio.ros2 import choose_transport

    choose_transport("large-data")  # as the node and the player (clouds through shared memory)
    rclpy.init()
    yield rclpy
    rclpy.try_shutdown()


@pytest.fixture(scope="session")
def urban(tmp_path_factory):
    """A generated urban sequence (SEQUENCE_S long, noise seed FARLIO_ROS_TEST_SEED or 1) and its
    dataset."""
    from farlio.datasets import open_dataset
    from farlio.simulation import generate

    path = tmp_path_factory.mktemp("ros2") / "urban"
    generate("urban", path, duration_s=SEQUENCE_S, seed=int(os.environ.get("FARLIO_ROS_TEST_SEED", "1")))
    return path, open_dataset(path)


@pytest.fixture
def recorder(ros):
    r = Recorder(ros)
    yield r
    r.close()


@pytest.fixture
def start_node(tmp_path):
    """start_node(*params) -> NodeProcess; every node still running at the end is stopped."""
    nodes: list[NodeProcess] = []

    def start(*params: str, params_file: Path | None = None) -> NodeProcess:
        nodes.append(NodeProcess(tmp_path / f"node{len(nodes)}.log", *params, params_file=params_file))
        return nodes[-1]

    yield start
    for n in nodes:
        if n.alive():
            n.stop()
