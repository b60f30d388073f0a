#!/usr/bin/env bash
# One command from a fresh Debian 12 checkout to a result: installs every dependency (Debian
# packages, PyPI into .venv), builds and installs the farlio Python package, generates a
# 10-second urban sequence with exact ground truth (the embedded default) and runs the
# LiDAR-inertial odometry on it, printing latency and accuracy. Outputs: out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
echo "[quickstart] building and installing the farlio package"
.venv/bin/python -m pip install -q --no-build-isolation .
.venv/bin/farlio simulate urban --duration 10 --out out/demo/urban --no-progress
.venv/bin/farlio run out/demo/urban --out out/demo/run
echo "[quickstart] done: trajectories, timings and eval plots are in out/demo/run"
