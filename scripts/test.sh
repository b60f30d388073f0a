#!/usr/bin/env bash
# Runs every test of farlio: the style check (clang-format, ruff), the C++ tests (ctest), the
# same C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer, the threaded tests (online
# odometry, replay) under ThreadSanitizer, and the Python tests
# (pytest) against the installed package, a 5 s fuzz smoke of every file reader (scripts/fuzz.sh),
# and the ROS 2 node over loopback (tests/ros2, in
# .venv-ros from scripts/install_ros2.sh; skipped without it). The
# GPU tests are built and skip without a GPU; scripts/gpu_check.sh runs them on one.
# Expects scripts/install_deps.sh to have run. Tests that need ../shared/data or a GPU skip
# cleanly when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
# ccache across clones of the repository (CI builds a fresh clone each time), nvcc included
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1 CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_CUDA_COMPILER_LAUNCHER=ccache
# The CUDA backend only has to compile and link here (no GPU): two architectures, the oldest and
# the newest of the default list (docs/cuda.md), instead of six; the C++ build and pip both read it.
export FARLIO_CUDA_ARCHITECTURES="${FARLIO_CUDA_ARCHITECTURES:-75;90}"

echo "== Format (clang-format, ruff) =="
bash scripts/check_format.sh

echo "== C++ build and tests (preset dev) =="
cmake --preset dev -DCMAKE_CUDA_ARCHITECTURES="$FARLIO_CUDA_ARCHITECTURES" >/dev/null
cmake --build --preset dev -j "$JOBS"
ctest --preset dev

echo "== Python package (pip install .) and tests =="
.venv/bin/python -m pip install -q --no-build-isolation .
.venv/bin/python -m pytest -q tests/python

echo "== ROS 2 node over loopback (.venv-ros, tests/ros2) =="
if [ -x .venv-ros/bin/python ] && .venv-ros/bin/python -c "import rclpy" 2>/dev/null; then
  bash scripts/install_ros2.sh --farlio-only  # this tree's farlio (the build above, not compiled again)
  .venv-ros/bin/python -m pytest -q -p no:warnings tests/ros2
else
  echo "skipped: no .venv-ros with rclpy (scripts/install_ros2.sh could not install the ROS 2 wheels)"
fi

if [ "${FARLIO_SKIP_FUZZ:-0}" != 1 ]; then
  echo "== Fuzz smoke of the file readers (scripts/fuzz.sh, 5 s a target) =="
  FUZZ_SECONDS=5 bash scripts/fuzz.sh
fi

if [ "${FARLIO_SKIP_SANITIZERS:-0}" != 1 ]; then
  echo "== C++ tests under ASan + UBSan (preset asan) =="
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j "$JOBS"
  ctest --preset asan
fi

if [ "${FARLIO_SKIP_TSAN:-0}" != 1 ]; then
  echo "== Threaded tests under TSan (preset tsan: online odometry, replay) =="
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -j "$JOBS"
  ctest --preset tsan
fi
