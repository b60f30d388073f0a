"""An optional live 3D view of a run with the `rerun-sdk` package (`farlio run --view`): every
registered scan in the world frame and the trajectory so far. Without a display the recording is
saved as run.rrd in the output folder, to open later with `rerun run.rrd`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

RECORDING_NAME = "farlio"
RRD_FILE = "run.rrd"
#: log every n-th point of a scan (a live view needs no full resolution)
POINT_STRIDE = 4


def rerun_module() -> Any:
    try:
        import rerun
    except ImportError:
        raise ValueError(
            "--view needs the 'rerun-sdk' package: pip install rerun-sdk (or run without --view)"
        ) from None
    return rerun


class RerunViewer:
    """on_frame callback for farlio.runner.run_dataset."""

    def __init__(self, out_dir: Path, spawn: bool = True):
        self.rr = rerun_module()
        self.rr.init(RECORDING_NAME)
        self.where = "the rerun viewer"
        try:
            if not spawn:
                raise RuntimeError("no viewer asked")
            self.rr.spawn()
        except Exception:  # no display or no viewer binary: keep the recording in a file
            self.where = str(Path(out_dir) / RRD_FILE)
            self.rr.save(self.where)
        self.path: list[np.ndarray] = []

    def __call__(self, i: int, scan: Any, frame: Any) -> None:
        pose = frame.scan.pose.matrix()
        pts = np.asarray(scan.points)[::POINT_STRIDE].astype(np.float64)
        world = pts @ pose[:3, :3].T + pose[:3, 3]
        self.path.append(pose[:3, 3].copy())
        self.rr.set_time("frame", sequence=i) if hasattr(self.rr, "set_time") else self.rr.set_time_sequence("frame", i)
        self.rr.log("world/scan", self.rr.Points3D(world.astype(np.float32)))
        self.rr.log("world/trajectory", self.rr.LineStrips3D([np.array(self.path, dtype=np.float32)]))
