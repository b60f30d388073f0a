"""The loopback harness of tests/ros2: the node and the player as subprocesses, a recorder node
in the test process (see conftest.py)."""

from __future__ import annotations

import random
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any, Callable

SEQUENCE_S = 6.0
#: how long a node has to start and be discovered, a player to finish, a node to stop
START_TIMEOUT_S, PLAY_TIMEOUT_S, STOP_TIMEOUT_S = 30.0, 120.0, 20.0
POLL_S = 0.02
#: half real time: on this shared 2-core machine a frame can take longer than a scan period at
#: times, and a scan arriving while the pipeline is busy is dropped (as in the paper); the tests
#: want every scan (the real-time rate is measured by figures/ros2_latency.py)
PLAY_RATE = 0.5
OUTPUTS = ("odometry", "scan_odometry", "cloud_registered", "diagnostics")
#: outputs published transient local (a late subscriber gets the last one)
LATCHED_OUTPUTS = ("global_map",)


def farlio_command(*args: str) -> list[str]:
    return [sys.executable, "-m", "farlio.cli", *args]


def wait_for(condition: Callable[[], bool], timeout_s: float, what: str | Callable[[], str]) -> None:
    """Polls condition until it holds; past timeout_s an AssertionError naming `what` (a callable:
    its text at that moment, e.g. what had arrived)."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            described = what() if callable(what) else what
            raise AssertionError(f"timed out after {timeout_s} s waiting for {described}")
        time.sleep(POLL_S)


def wait_for_diagnostics(recorder: Recorder, n: int, node: NodeProcess, played: str = "") -> None:
    """Waits for the node's first n scan diagnostics; on a timeout the error says how many came,
    the last messages, the node's log and the player's output (to tell a scan the node dropped
    from one that never reached it)."""

    def described() -> str:
        messages = [d["message"] for d in recorder.diagnostics()][-5:]
        return (
            f"{n} scan diagnostics (received {recorder.count('diagnostics')}, the last: {messages})\n"
            f"node log:\n{node.text()[-3000:]}\nplayer output:\n{played[-2000:]}"
        )

    wait_for(lambda: recorder.count("diagnostics") >= n, START_TIMEOUT_S, described)


class NodeProcess:
    """`farlio ros2 --ros-args [--params-file F] -p name:=value ...` in a subprocess, its output in
    `log`."""

    def __init__(self, log: Path, *params: str, params_file: Path | None = None):
        args = (["--params-file", str(params_file)] if params_file else []) + [a for p in params for a in ("-p", p)]
        self.log = log
        self._out = open(log, "w")  # noqa: SIM115 - closed in stop()
        self.proc = subprocess.Popen(
            farlio_command("ros2", "--ros-args", *args), stdout=self._out, stderr=subprocess.STDOUT
        )

    def alive(self) -> bool:
        return self.proc.poll() is None

    def stop(self, sig: int = signal.SIGINT) -> int:
        """SIGINT, as Ctrl-C does (or `sig`); the exit status."""
        if self.alive():
            self.proc.send_signal(sig)
        try:
            rc = self.proc.wait(STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            rc = self.proc.wait()
        self._out.close()
        return rc

    def text(self) -> str:
        return self.log.read_text()


class Recorder:
    """Subscribes to the node's outputs (reliable) and keeps (arrival monotonic ns, message); spins
    in a thread of its own."""

    def __init__(self, rclpy: Any, node_name: str = "farlio", extra: tuple[str, ...] = ()):
        """`extra`: outputs recorded besides OUTPUTS, of EXTRA_TYPES (latched ones transient local)."""
        from diagnostic_msgs.msg import DiagnosticArray
        from nav_msgs.msg import Odometry
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from sensor_msgs.msg import PointCloud2

        self.node = rclpy.create_node(f"farlio_test_recorder_{random.randint(0, 1 << 30)}")
        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        types = {"odometry": Odometry, "scan_odometry": Odometry, "cloud_registered": PointCloud2}
        types["diagnostics"] = DiagnosticArray
        types.update({"global_odometry": Odometry, "global_map": PointCloud2})
        latched = QoSProfile(
            depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
        )
        outputs = OUTPUTS + tuple(extra)
        self.msgs: dict[str, list[tuple[int, Any]]] = {k: [] for k in outputs}
        self.subs = [
            self.node.create_subscription(
                types[k], f"/{node_name}/{k}", self._keep(k), latched if k in LATCHED_OUTPUTS else qos
            )
            for k in outputs
        ]
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self.executor.spin, daemon=True)
        self._thread.start()

    def _keep(self, key: str) -> Callable[[Any], None]:
        def keep(msg: Any) -> None:
            if key == "cloud_registered":  # no point data kept
                msg.data = []
            self.msgs[key].append((time.monotonic_ns(), msg))

        return keep

    def wait_for_node(self, node: NodeProcess | None = None) -> None:
        """Until the node's publishers are matched (discovery done)."""

        def ready() -> bool:
            if node is not None and not node.alive():
                raise AssertionError(f"the node exited:\n{node.text()}")
            return all(s.get_publisher_count() > 0 for s in self.subs)

        wait_for(ready, START_TIMEOUT_S, "the node's publishers")

    def count(self, key: str) -> int:
        return len(self.msgs[key])

    def diagnostics(self) -> list[dict[str, str]]:
        """Every diagnostics message as {key: value} (with 'message' and 'level')."""
        out = []
        for _, m in self.msgs["diagnostics"]:
            s = m.status[0]
            out.append(
                {**{kv.key: kv.value for kv in s.values}, "message": s.message, "level": int.from_bytes(s.level)}
            )
        return out

    def save_map(self) -> Any:
        from std_srvs.srv import Trigger

        client = self.node.create_client(Trigger, "/farlio/save_map")
        assert client.wait_for_service(timeout_sec=START_TIMEOUT_S)
        future = client.call_async(Trigger.Request())
        wait_for(future.done, START_TIMEOUT_S, "the save_map response")
        return future.result()

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


def play(sequence: Path, *args: str) -> str:
    """`farlio ros2-play sequence args...` at PLAY_RATE to its end; its output (stdout, then its
    log on stderr). The player waits up to START_TIMEOUT_S for the node's subscriptions: with its
    default wait a loaded machine had it play before discovery was done, and the first scans were
    lost (the suite's occasional timeouts waiting for diagnostics)."""
    r = subprocess.run(
        farlio_command(
            "ros2-play", str(sequence), "--rate", str(PLAY_RATE), "--wait-subscribers", str(START_TIMEOUT_S), *args
        ),
        capture_output=True,
        text=True,
        timeout=PLAY_TIMEOUT_S + START_TIMEOUT_S,
    )
    out = r.stdout + r.stderr
    assert r.returncode == 0, out
    assert "playing anyway" not in out, f"the player did not discover the node's subscriptions:\n{out}"
    return out
