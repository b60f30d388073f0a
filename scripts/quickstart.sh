#!/usr/bin/env bash
# One command from a fresh Debian 12 checkout to a result: installs every dependency (Debian
# packages, PyPI into .venv), builds and installs the farlio Python package (the CUDA backend only
# where a GPU is present), and runs the LiDAR-inertial odometry on the embedded default, 45 s of
# the generated urban drive (about 430 m down a street and round a corner) served from memory,
# printing latency and accuracy against the exact ground truth and saving the whole map
# (`farlio demo`; a few MB on disk). Outputs: out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
echo "[quickstart] building and installing the farlio package"
.venv/bin/python -m pip install -q --no-build-isolation .
if ! .venv/bin/python -c "import farlio, sys; sys.exit(not farlio.cuda_compiled())"; then
  echo "[quickstart] no GPU on this machine: the CUDA backend was not built, farlio runs on the CPU" \
    "(FARLIO_CUDA=ON .venv/bin/python -m pip install --no-build-isolation . builds it anyway)"
fi
.venv/bin/farlio demo --out out/demo --no-progress
echo "[quickstart] done: out/demo/map.png (the map from above, coloured by height, with the path),"
echo "             out/demo/trajectory.png (the path with the ground truth); map.pcd, map.ply,"
echo "             the trajectories, timing.csv and summary.json beside them"
