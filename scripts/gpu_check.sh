#!/usr/bin/env bash
# The GPU check of the CUDA backend, in one call on a machine with an NVIDIA GPU:
#   1. build Release for this GPU's architecture (or take a build packed with --pack, below);
#   2. run the GPU tests (GPU vs CPU: map contents, k-NN, covariances, 100-frame trajectory);
#   3. time the scan pipeline, GPU and CPU on the same scans (bench/gpu_pipeline): generated
#      urban and racetrack sequences and, with SCANS=DIR, a folder of recorded scans: median, p99
#      and max per frame, each stage's median and p99, device memory, CPU/GPU agreement, the
#      scan's upload, k-NN and reduction bandwidth against a device-to-device copy;
#   4. run the GPU tests under compute-sanitizer memcheck, racecheck and initcheck (without the
#      100-frame and odometry tests, whose kernels the short pipeline test runs too);
#   5. with NCU=1: Nsight Compute's duration of every kernel over 20 urban frames, summed per
#      kernel and per frame (scripts/gpu_kernel_table.py), against the frame's wall time;
#   5b. with BASELINE=DIR (a build of another commit, made by --pack): its gpu_pipeline on the same
#      scans between two more runs of this build's (GPU only), and with NCU=1 its kernel profile
#      too: before and after on one machine in one call;
#   6. with PYTHON=1: build the Python package there (pip, no index: the GPU image's own
#      scikit-build-core, nanobind, numpy, matplotlib, PyYAML) and run the command line tool on the
#      GPU: `farlio run --device cuda` and `--device cpu` on a generated 10 s urban sequence (their
#      summaries side by side), then `farlio bench --device cuda` (and on SCANS).
# Every step runs even when an earlier one failed, under its own time limit; the logs go to
# $OUT (or $BUILD/gpu_check) and a summary of the steps is printed last. The exit status is 0
# only if every step passed; 3 when compute-sanitizer is missing, so that a run without the
# sanitizers cannot pass for one with them.
# Environment: BUILD (default build/gpu), CUDA_ARCH (default native), FRAMES (default 100),
# JOBS (default nproc), SCANS (a folder of scans for the timing), SKIP_SANITIZERS=1,
# PREBUILT (a folder made by --pack: run its binaries, build nothing), BASELINE (likewise, the
# build to compare with), BASELINE_ARGS (what its profiled gpu_pipeline is given to run each
# sequence once: --no-staged, the default; '' for a build older than that option), NCU=1, PYTHON=1.
#
#   scripts/gpu_check.sh --pack DIR   (on the build machine, after building BUILD with CUDA)
# copies the two executables, stripped, and the shared libraries they need that are not the C
# and C++ runtime into DIR/bin and DIR/lib, so that a GPU machine without the build dependencies
# (or with too little time to build) can run PREBUILT=DIR scripts/gpu_check.sh.
#
#   scripts/gpu_check.sh --fetch-debs
# downloads the build dependencies (Eigen, TBB, yaml-cpp, GoogleTest) as Debian 12 packages into
# .gpu-debs/ (ignored by git); carried to a GPU image without them, the script unpacks them into
# .gpu-debs/root (never into /) and builds against them.
set -uo pipefail
cd "$(dirname "$0")/.."

BUILD=${BUILD:-build/gpu}
EXECUTABLES=(tests/cuda/test_cuda_backend bench/gpu_pipeline)
DEBS=.gpu-debs
DEB_PACKAGES=(libeigen3-dev libtbb-dev libtbb12 libtbbmalloc2 libtbbbind-2-5 libhwloc15 libyaml-cpp-dev
              libyaml-cpp0.7 libgtest-dev googletest zlib1g-dev zlib1g)
# The libraries every Linux machine has (C runtime, C++ runtime, the dynamic loader): not packed.
SYSTEM_LIBS='^(linux-vdso|libc\.|libm\.|libdl\.|libpthread\.|librt\.|libgcc_s\.|libstdc\+\+\.|ld-linux)'

case "${1:-}" in
  --fetch-debs)
    mkdir -p "$DEBS"
    (cd "$DEBS" && apt-get download "${DEB_PACKAGES[@]}")
    echo "downloaded into $DEBS: carry it to the GPU machine"
    exit 0 ;;
  --pack)
    dest=${2:?--pack needs a folder}
    mkdir -p "$dest/bin" "$dest/lib"
    for exe in "${EXECUTABLES[@]}"; do
      [ -x "$BUILD/$exe" ] || { echo "missing $BUILD/$exe: build it first" >&2; exit 2; }
      strip -o "$dest/bin/$(basename "$exe")" "$BUILD/$exe"
      ldd "$BUILD/$exe" | awk '$3 ~ /^\// {print $3}' | while read -r lib; do
        basename "$lib" | grep -Eq "$SYSTEM_LIBS" || cp -L "$lib" "$dest/lib/"
      done
    done
    du -sh "$dest/bin" "$dest/lib"
    exit 0 ;;
esac

CUDA_ARCH=${CUDA_ARCH:-native}
FRAMES=${FRAMES:-100}
JOBS=${JOBS:-$(nproc)}
CUDA_BIN=/usr/local/cuda/bin
export PATH="$PATH:$CUDA_BIN"
# the long GPU-vs-CPU runs stay out of the sanitizer runs (the short pipeline test runs every kernel);
# racecheck (shared-memory hazards, 40-50 s a test of a dozen frames) skips the staging tests too,
# which run no kernel of their own: memcheck and initcheck check their reads of the staged scans
LONG_TESTS=CudaPipeline.HundredUrbanFramesAgreeWithTheCpu:CudaOdometry.*
STAGING_TESTS=CudaPipeline.ScansStaged*:CudaPipeline.AScanOtherThanTheStaged*
LOGS=${OUT:-$BUILD/gpu_check}
mkdir -p "$LOGS"
# seconds each step may take (one lease of a GPU machine holds all of them)
TESTS_LIMIT_S=${TESTS_LIMIT_S:-120}
BENCH_LIMIT_S=${BENCH_LIMIT_S:-180}
SANITIZER_LIMIT_S=${SANITIZER_LIMIT_S:-150}
PYTHON_LIMIT_S=${PYTHON_LIMIT_S:-420}

summary=()
status=0
# step NAME LOG COMMAND...: runs the command under its time limit, its output into LOG and on
# the terminal, and notes how it ended.
step() {
  local name=$1 log=$2 limit=$3
  shift 3
  echo "== $name =="
  local start=$SECONDS
  timeout "$limit" "$@" 2>&1 | tee "$LOGS/$log"
  local rc=${PIPESTATUS[0]}
  local verdict=passed
  [ "$rc" = 124 ] && verdict="stopped after ${limit} s" || { [ "$rc" != 0 ] && verdict="FAILED (exit $rc)"; }
  summary+=("$(printf '%-28s %-22s %4d s   %s' "$name" "$verdict" $((SECONDS - start)) "$LOGS/$log")")
  return "$rc"
}

echo "== GPU =="
nvidia-smi --query-gpu=name,memory.total,driver_version,clocks.sm,clocks.max.sm --format=csv,noheader || true

echo "host: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) threads"

# The build dependencies from .gpu-debs (--fetch-debs), when there: unpacked once, for CMake.
use_debs() {
  compgen -G "$DEBS/*.deb" >/dev/null || return 0
  [ -n "${DEBS_IN_USE:-}" ] && return 0
  local root="$PWD/$DEBS/root"
  mkdir -p "$root"
  for deb in "$DEBS"/*.deb; do dpkg-deb -x "$deb" "$root"; done
  # Debian's development links are absolute (/lib/...): point them into the unpacked tree
  local link
  for link in "$root"/usr/lib/x86_64-linux-gnu/*.so; do
    [ -L "$link" ] && [ "$(readlink "$link" | cut -c1)" = / ] && ln -sf "$root$(readlink "$link")" "$link"
  done
  export CMAKE_PREFIX_PATH="$root/usr${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
  export LD_LIBRARY_PATH="$root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  DEBS_IN_USE=1
  echo "== build dependencies from $DEBS (unpacked into $root) =="
}

build_here() {
  use_debs
  echo "== build (CUDA architectures: $CUDA_ARCH) =="
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  cmake -S . -B "$BUILD" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DFARLIO_CUDA=ON \
    -DCMAKE_CUDA_ARCHITECTURES="$CUDA_ARCH" -DFARLIO_BUILD_TESTS=ON -DFARLIO_BUILD_BENCHMARKS=ON >/dev/null &&
    cmake --build "$BUILD" -j "$JOBS" --target test_cuda_backend gpu_pipeline || exit 2
  bin="$BUILD/bin"
  mkdir -p "$bin"
  for exe in "${EXECUTABLES[@]}"; do ln -sf "$PWD/$BUILD/$exe" "$bin/"; done
}

if [ -n "${PREBUILT:-}" ]; then
  bin="$PREBUILT/bin"
  export LD_LIBRARY_PATH="$PWD/$PREBUILT/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  echo "== prebuilt executables from $PREBUILT =="
  if ! "$bin/test_cuda_backend" --gtest_list_tests >/dev/null || ! "$bin/gpu_pipeline" --frames 0 --device cpu >/dev/null; then
    echo "the prebuilt executables do not run here: building instead" >&2
    build_here
  fi
else
  build_here
fi

step "GPU tests" tests.log "$TESTS_LIMIT_S" "$bin/test_cuda_backend" || status=1

bench_args=(--frames "$FRAMES" --profile urban --profile racetrack)
[ -n "${SCANS:-}" ] && bench_args+=(--scans "$SCANS")
step "scan pipeline timing" timing.log "$BENCH_LIMIT_S" "$bin/gpu_pipeline" "${bench_args[@]}" || status=1

# The baseline build on the same scans, between two more runs of this one (GPU only).
if [ -n "${BASELINE:-}" ]; then
  step "baseline timing" baseline_timing.log "$BENCH_LIMIT_S" env LD_LIBRARY_PATH="$PWD/$BASELINE/lib:${LD_LIBRARY_PATH:-}" \
    "$BASELINE/bin/gpu_pipeline" "${bench_args[@]}" --no-cpu-compare --repeats 0 || status=1
  step "scan pipeline timing again" timing_again.log "$BENCH_LIMIT_S" "$bin/gpu_pipeline" "${bench_args[@]}" \
    --no-cpu-compare --repeats 0 || status=1
fi

if [ "${SKIP_SANITIZERS:-0}" != 1 ]; then
  SANITIZER=$(command -v compute-sanitizer || true)
  if [ -z "$SANITIZER" ]; then
    echo "compute-sanitizer not found (PATH, $CUDA_BIN): sanitizer runs NOT done" >&2
    summary+=("compute-sanitizer            NOT FOUND")
    [ "$status" = 0 ] && status=3
  else
    for tool in memcheck racecheck initcheck; do
      skip=$LONG_TESTS
      [ "$tool" = racecheck ] && skip=$LONG_TESTS:$STAGING_TESTS
      step "compute-sanitizer $tool" "$tool.log" "$SANITIZER_LIMIT_S" "$SANITIZER" --tool "$tool" --error-exitcode 1 \
        "$bin/test_cuda_backend" --gtest_filter="-$skip" || status=1
    done
  fi
fi

# Where a frame's device time goes (step 5): every kernel's duration, replayed by ncu (its own
# clocks left alone), over NCU_FRAMES urban frames without the bandwidth samples.
NCU_FRAMES=${NCU_FRAMES:-20}
if [ "${NCU:-0}" = 1 ]; then
  NCU_BIN=$(command -v ncu || true)
  if [ -z "$NCU_BIN" ]; then
    summary+=("kernel profile (ncu)         NOT FOUND")
  else
    # kernel_profile NAME BIN_DIR LIBS CSV [ARGS]: ncu's durations of that build's kernels, per
    # frame, over one run of the frames (this build's --no-staged: not the second, staged run)
    kernel_profile() {
      step "$1" "$4.log" "$BENCH_LIMIT_S" bash -c "LD_LIBRARY_PATH='$3' '$NCU_BIN' --clock-control none --metrics \
        gpu__time_duration.sum --csv --page raw '$2/gpu_pipeline' --frames $NCU_FRAMES --profile urban \
        --no-cpu-compare --repeats 0 ${5:-} > '$LOGS/$4.csv' && python3 scripts/gpu_kernel_table.py '$LOGS/$4.csv' $NCU_FRAMES"
    }
    kernel_profile "kernel profile (ncu)" "$bin" "${LD_LIBRARY_PATH:-}" ncu --no-staged || status=1
    if [ -n "${BASELINE:-}" ]; then
      # a build from before --no-staged (BASELINE_ARGS='' for one) ran each sequence once
      kernel_profile "baseline kernel profile (ncu)" "$BASELINE/bin" "$PWD/$BASELINE/lib:${LD_LIBRARY_PATH:-}" \
        ncu_baseline "${BASELINE_ARGS---no-staged}" || status=1
    fi
  fi
fi

# The Python package and the command line tool on the GPU (step 6).
python_check() {
  local site=/tmp/farlio-gpu-site seq=/tmp/farlio-gpu-seq runs=/tmp/farlio-gpu-runs
  rm -rf "$site" "$seq" "$runs"
  echo "-- pip install (Release, CUDA architectures $CUDA_ARCH) --"
  FARLIO_CUDA=ON FARLIO_CUDA_ARCHITECTURES="$CUDA_ARCH" CMAKE_BUILD_PARALLEL_LEVEL="$JOBS" \
    python3 -m pip install -q --no-build-isolation --no-deps --no-index --target "$site" . || return 1
  export PYTHONPATH="$site${PYTHONPATH:+:$PYTHONPATH}"
  local farlio=(python3 -c "import sys; from farlio.cli import main; sys.exit(main())")
  "${farlio[@]}" info || return 1
  "${farlio[@]}" simulate urban --duration 10 --out "$seq" --no-progress >/dev/null || return 1
  for device in cuda cpu; do
    "${farlio[@]}" run "$seq" --device "$device" --out "$runs/$device" --no-plot --no-progress || return 1
  done
  python3 - "$runs" <<'PY' || return 1
import json, sys
for device in ("cuda", "cpu"):
    s = json.load(open(f"{sys.argv[1]}/{device}/summary.json"))
    a = s["accuracy"]
    print(f"farlio run --device {device}: ran on {s['device']}, {s['frames']} frames, {s['fused']} fused, "
          f"latency {s['latency_ms']}, APE {a['ape']['translation_m']['rmse']:.4f} m / "
          f"{a['ape']['rotation_deg']['rmse']:.3f} deg, KITTI RPE {json.dumps(a.get('kitti_rpe'))[:160]}")
PY
  local data=()
  [ -n "${SCANS:-}" ] && data=(--data "$SCANS")
  "${farlio[@]}" bench --profile urban --scans "$FRAMES" "${data[@]}" --device cuda --no-kiss
}
if [ "${PYTHON:-0}" = 1 ]; then
  use_debs
  python3 -c "import sys, sysconfig, os; h = sysconfig.get_paths()['include']; print(sys.version.split()[0], h, 'Python.h:', os.path.exists(h + '/Python.h'))"
  step "Python package on the GPU" python.log "$PYTHON_LIMIT_S" bash -c "$(declare -f python_check); \
    CUDA_ARCH='$CUDA_ARCH' JOBS='$JOBS' FRAMES='$FRAMES' SCANS='${SCANS:-}' python_check" || status=1
fi

echo "== summary =="
printf '%s\n' "${summary[@]}" | tee "$LOGS/summary.txt"
cat "$LOGS/timing.log" 2>/dev/null || true
[ -n "${BASELINE:-}" ] && grep -h -A1 '^urban\|^racetrack\|^kitti\|^scans' "$LOGS/baseline_timing.log" "$LOGS/timing_again.log" 2>/dev/null
grep -h 'agreement\|preallocates\|FAILED' "$LOGS/tests.log" || true
grep -h 'ERROR SUMMARY\|RACECHECK SUMMARY' "$LOGS"/*check.log 2>/dev/null || true
exit "$status"
