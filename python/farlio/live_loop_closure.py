"""Loop closure beside a live odometry (the ROS 2 node's `loop_closure` parameter): the same back
end as `farlio run --loop-closure` (loop_closure.LoopClosure: keyframes, verified loops, the pose
graph) on a thread of its own, fed with the scans the online odometry registered, so that the
odometry never waits for a verification or a graph update.

The odometry's thread hands over each registered scan (`submit`: a queue append, nothing else).
The back end's thread builds the keyframes from the scans' registered points, verifies the loop
candidates and updates the graph; after every keyframe it publishes, under a short lock:

- `map_from_odometry()`: REP 105's map -> odom correction (4x4), the newest keyframe's global pose
  times the inverse of its odometry pose; the global pose of anything the odometry reports is this
  times its odometry pose;
- `take_global_map()`: every keyframe segment at its global pose, at most every
  global_map_period_s and only when a keyframe or a loop came since the last one;
- `stats()`: keyframes, loops accepted and verified, the scans waiting, the scans dropped.

The back end's threads run BACK_END_NICENESS nicer than the odometry's, so that on a machine
with few cores a verification waits for the odometry rather than the other way round. The queue
holds at most MAX_BACKLOG_SCANS scans; a scan arriving when it is full is dropped from
the back end (counted; its keyframe's segment has fewer points), never from the odometry."""

from __future__ import annotations

import queue
import threading
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from .loop_closure import LoopClosure, lower_priority

#: scans waiting for the back end (about 30 s of a 20 Hz LiDAR) before new ones are dropped from it
MAX_BACKLOG_SCANS = 600
#: the back end's threads run this much nicer than the odometry's (Linux): on a machine with few
#: cores the odometry's worker takes a core first, and the verification waits
BACK_END_NICENESS = 10
#: how long the back end's thread waits for a scan before it looks at its stop flag (s)
POLL_S = 0.1


@dataclass
class LoopStats:
    """What the back end has done (the node's diagnostics)."""

    keyframes: int = 0
    loops_accepted: int = 0
    loops_verified: int = 0
    backlog_scans: int = 0
    scans_dropped: int = 0


class LiveLoopClosure:
    """LoopClosure on its own thread, fed with registered scans (see the module doc)."""

    def __init__(self, config: Any, T_imu_lidar: Any, resolution_m: float, global_map_period_s: float = 5.0):
        self.loops = LoopClosure(config, T_imu_lidar, BACK_END_NICENESS)
        self.loops.resolution_m = resolution_m
        self.global_map_period_s = global_map_period_s
        self._queue: queue.Queue[tuple[int, np.ndarray, np.ndarray]] = queue.Queue(MAX_BACKLOG_SCANS)
        self._lock = threading.Lock()
        self._map_from_odometry = np.eye(4)
        self._stats = LoopStats()
        self._global_map: np.ndarray | None = None
        self._map_made_s = -float("inf")
        self._map_version = 0  # closed segments + loops when the map was made
        self._stop = threading.Event()
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="farlio-loops", daemon=True)
        self._thread.start()

    # ---- the odometry's side ------------------------------------------------------------------
    def submit(self, stamp_ns: int, T_lidar: np.ndarray, points: np.ndarray) -> bool:
        """Hands over a registered scan (its LiDAR pose in the odometry's frame and its points in
        that frame); False when the back end is MAX_BACKLOG_SCANS behind and drops it."""
        try:
            self._queue.put_nowait((stamp_ns, np.array(T_lidar, dtype=np.float64), points))
            return True
        except queue.Full:
            with self._lock:
                self._stats.scans_dropped += 1
            return False

    def map_from_odometry(self) -> np.ndarray:
        """The map -> odom correction (4x4) as of the newest keyframe."""
        with self._lock:
            return self._map_from_odometry.copy()

    def take_global_map(self) -> np.ndarray | None:
        """The global map ((N, 3) float32) made since the last call, or None."""
        with self._lock:
            points, self._global_map = self._global_map, None
            return points

    @property
    def native_thread_id(self) -> int | None:
        """The back end's thread as the OS knows it (for its priority, or a profiler)."""
        return self._thread.native_id

    @property
    def error(self) -> str | None:
        """What stopped the back end (it skips the scans after it), or None while it works."""
        e = self._error
        return None if e is None else f"{type(e).__name__}: {e}"

    def stats(self) -> LoopStats:
        with self._lock:
            s = LoopStats(**vars(self._stats))
        s.backlog_scans = self._queue.qsize()
        return s

    def stop(self, drain: bool = True) -> None:
        """Ends the back end's thread, after the scans waiting (drain) or at once; raises what the
        thread raised, if anything."""
        if drain:
            self._queue.join()
        self._stop.set()
        self._thread.join()
        if self._error is not None:
            raise self._error

    # ---- the back end's thread ----------------------------------------------------------------
    def _run(self) -> None:
        lower_priority(BACK_END_NICENESS)
        while not self._stop.is_set():
            try:
                item = self._queue.get(timeout=POLL_S)
            except queue.Empty:
                continue
            try:
                if self._error is None:
                    self._add(*item)
            except Exception as e:  # kept for stop(); the odometry goes on without loop closure
                self._error = e
            finally:
                self._queue.task_done()

    def _add(self, stamp_ns: int, T_lidar: np.ndarray, points: np.ndarray) -> None:
        loops = self.loops
        keyframes = len(loops.keyframes)
        loops.add_registered(stamp_ns, T_lidar, points)
        if len(loops.keyframes) == keyframes:
            return
        accepted = sum(r.accepted for r in loops.records)
        correction = loops.map_from_odometry()
        version = len(loops.keyframes) - 1 + accepted  # closed segments and loops
        now = time.monotonic()
        global_map = None
        if version != self._map_version and now - self._map_made_s >= self.global_map_period_s:
            global_map, self._map_version, self._map_made_s = loops.global_points(), version, now
        with self._lock:
            self._map_from_odometry = correction
            self._stats.keyframes = len(loops.keyframes)
            self._stats.loops_accepted = accepted
            self._stats.loops_verified = len(loops.records)
            if global_map is not None:
                self._global_map = global_map
