"""farlio: fast, accurate, robust LiDAR-inertial odometry (FAR-LIO) with CPU and CUDA backends.

The C++ core is reached through :mod:`farlio._core`; the most used types are re-exported here.
"""

from __future__ import annotations

from ._core import (  # noqa: F401
    SE3,
    Config,
    ImuSample,
    InputError,
    Odometry,
    OnlineOdometry,
    Scan,
    ScanPipeline,
    Trajectory,
    cuda_compiled,
    cuda_device_count,
    io,  # noqa: F401
    register_pair,
    sim,  # noqa: F401
)
from ._core import eval as _eval_ext  # noqa: F401

__version__ = "0.1.0"
