#!/usr/bin/env bash
# Runs every test of farlio: the C++ tests (ctest), the same C++ tests under AddressSanitizer +
# UndefinedBehaviorSanitizer, and the Python tests (pytest) against the installed package.
# Expects scripts/install_deps.sh to have run. Tests that need ../shared/data or a GPU skip
# cleanly when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
# ccache across clones of the repository (CI builds a fresh clone each time)
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1 CMAKE_CXX_COMPILER_LAUNCHER=ccache

echo "== C++ build and tests (preset dev) =="
cmake --preset dev >/dev/null
cmake --build --preset dev -j "$JOBS"
ctest --preset dev

echo "== Python package (pip install .) and tests =="
.venv/bin/python -m pip install -q --no-build-isolation .
.venv/bin/python -m pytest -q tests/python

if [ "${FARLIO_SKIP_SANITIZERS:-0}" != 1 ]; then
  echo "== C++ tests under ASan + UBSan (preset asan) =="
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j "$JOBS"
  ctest --preset asan
fi
