#!/usr/bin/env bash
# Installs every system dependency of farlio from Debian 12's packages, then creates the
# project's Python virtual environment (.venv) with the build and test tools from PyPI.
# Nothing is downloaded from anywhere else. Safe to run again (idempotent).
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(
  build-essential cmake ninja-build pkg-config ccache clang-format
  libeigen3-dev libtbb-dev libyaml-cpp-dev zlib1g-dev
  libgtest-dev libbenchmark-dev
  python3 python3-dev python3-venv
)

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "[install] apt packages: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "[install] creating .venv with $($PY --version)"
  $PY -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
# Build backend and test tools (versions pinned to what the project is tested with).
.venv/bin/python -m pip install -q -r scripts/requirements-dev.txt
# ouster-sdk 1.0.1 pins rosbags==0.9.23, which evo (rosbags>=0.11.1) excludes, and flask/nanobind
# versions; farlio uses only its packet decoding (ouster.sdk.core, ouster.sdk.pcap), which needs
# numpy, more-itertools and rosbags at import: install it without its pins.
.venv/bin/python -m pip install -q --no-deps ouster-sdk==1.0.1
