#!/usr/bin/env bash
# One command from a fresh Debian 12 checkout to a result: installs every dependency (Debian
# packages, PyPI into .venv), builds and installs the farlio Python package, generates 45 s of
# the urban drive with exact ground truth (the embedded default: about 430 m down a street and
# round a corner; 1.1 GB of scans) and runs the LiDAR-inertial odometry on it, printing latency
# and accuracy, and saves the whole map. Outputs: out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
echo "[quickstart] building and installing the farlio package"
.venv/bin/python -m pip install -q --no-build-isolation .
.venv/bin/farlio simulate urban --duration 45 --out out/demo/urban --no-progress
.venv/bin/farlio run out/demo/urban --out out/demo/run --save-map
echo "[quickstart] done: out/demo/run/map.png (the map from above, coloured by height, with the path),"
echo "             out/demo/run/trajectory.png (the path with the ground truth); map.pcd, map.ply,"
echo "             the trajectories, timing.csv and summary.json beside them"
