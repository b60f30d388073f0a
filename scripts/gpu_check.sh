#!/usr/bin/env bash
# The GPU check of the CUDA backend, in one call on a machine with an NVIDIA GPU, the repository
# and the Debian packages of scripts/install_deps.sh (no .venv needed):
#   1. configure and build with CUDA (Release, this GPU's architecture);
#   2. run the GPU tests (GPU vs CPU: map contents, k-NN, covariances, 100-frame trajectory);
#   3. run them under compute-sanitizer memcheck and racecheck (without the 100-frame test,
#      whose kernels the short pipeline test runs too);
#   4. time the scan pipeline on generated urban and racetrack sequences (bench/gpu_pipeline):
#      median, p99, device memory, CPU/GPU agreement, k-NN and reduction bandwidth vs a copy.
# Environment: BUILD (build folder, default build/gpu), CUDA_ARCH (default native), FRAMES
# (default 100), JOBS (default nproc), SKIP_SANITIZERS=1.
#
# A GPU image without the build dependencies (Eigen, TBB, yaml-cpp, GoogleTest) can take them
# as Debian 12 packages: run `scripts/gpu_check.sh --fetch-debs` on a Debian machine first (it
# downloads them into .gpu-debs/, which git ignores), carry .gpu-debs to the GPU machine, and this
# script unpacks them into .gpu-debs/root (never into /) and builds against them.
set -euo pipefail
cd "$(dirname "$0")/.."

DEBS=.gpu-debs
DEB_PACKAGES=(libeigen3-dev libtbb-dev libtbb12 libtbbmalloc2 libtbbbind-2-5 libhwloc15 libyaml-cpp-dev
              libyaml-cpp0.7 libgtest-dev googletest zlib1g-dev)
if [ "${1:-}" = --fetch-debs ]; then
  mkdir -p "$DEBS"
  (cd "$DEBS" && apt-get download "${DEB_PACKAGES[@]}")
  echo "downloaded into $DEBS: carry it to the GPU machine"
  exit 0
fi
if compgen -G "$DEBS/*.deb" >/dev/null; then
  root="$PWD/$DEBS/root"
  mkdir -p "$root"
  for deb in "$DEBS"/*.deb; do dpkg-deb -x "$deb" "$root"; done
  export CMAKE_PREFIX_PATH="$root/usr${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
  export LD_LIBRARY_PATH="$root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  echo "== build dependencies from $DEBS (unpacked into $root) =="
fi
BUILD=${BUILD:-build/gpu}
CUDA_ARCH=${CUDA_ARCH:-native}
FRAMES=${FRAMES:-100}
JOBS=${JOBS:-$(nproc)}
CUDA_BIN=/usr/local/cuda/bin
export PATH="$PATH:$CUDA_BIN"
LONG_TEST=CudaPipeline.HundredUrbanFramesAgreeWithTheCpu

echo "== GPU =="
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true

echo "== build (CUDA architectures: $CUDA_ARCH) =="
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
cmake -S . -B "$BUILD" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DFARLIO_CUDA=ON \
  -DCMAKE_CUDA_ARCHITECTURES="$CUDA_ARCH" -DFARLIO_BUILD_TESTS=ON -DFARLIO_BUILD_BENCHMARKS=ON >/dev/null
cmake --build "$BUILD" -j "$JOBS" --target test_cuda_backend gpu_pipeline

echo "== GPU tests =="
"$BUILD/tests/cuda/test_cuda_backend"

sanitizer_status=0
if [ "${SKIP_SANITIZERS:-0}" != 1 ]; then
  SANITIZER=$(command -v compute-sanitizer || true)
  if [ -z "$SANITIZER" ]; then
    echo "compute-sanitizer not found (PATH, $CUDA_BIN): sanitizer runs NOT done" >&2
    sanitizer_status=3
  else
    for tool in memcheck racecheck; do
      echo "== compute-sanitizer --tool $tool =="
      "$SANITIZER" --tool "$tool" --error-exitcode 1 "$BUILD/tests/cuda/test_cuda_backend" --gtest_filter="-$LONG_TEST"
    done
  fi
fi

echo "== scan pipeline timing ($FRAMES frames per sequence) =="
"$BUILD/bench/gpu_pipeline" --frames "$FRAMES" --profile urban --profile racetrack
exit "$sanitizer_status"
