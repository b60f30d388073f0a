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
set -euo pipefail
cd "$(dirname "$0")/.."
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

if [ "${SKIP_SANITIZERS:-0}" != 1 ]; then
  for tool in memcheck racecheck; do
    echo "== compute-sanitizer --tool $tool =="
    "$CUDA_BIN/compute-sanitizer" --tool "$tool" --error-exitcode 1 \
      "$BUILD/tests/cuda/test_cuda_backend" --gtest_filter="-$LONG_TEST"
  done
fi

echo "== scan pipeline timing ($FRAMES frames per sequence) =="
"$BUILD/bench/gpu_pipeline" --frames "$FRAMES" --profile urban --profile racetrack
