#!/usr/bin/env bash
# Fuzzes every C++ file reader with libFuzzer (clang from Debian, ASan + UBSan): PCD (whole files,
# and the ascii, binary and binary_compressed data sections), PLY, KITTI .bin, LZF, imu.csv,
# calib.yaml, TUM, KITTI poses and times files (targets in fuzz/). Each target runs for
# FUZZ_SECONDS (default 60), seeded with fuzz/seeds/<target> and with seeds made from the real
# files in ../shared/data (real/ and bad/; fuzz/make_seeds.py) when it is there. Prints the
# executions per target and fails (exit 1) if any target found a crash, a hang, a leak or a
# memory blow-up; the input that did it is kept in build/fuzz/findings/.
#
#   FUZZ_SECONDS=5 scripts/fuzz.sh          # the smoke run (CI)
#   FUZZ_TARGETS="pcd ply" scripts/fuzz.sh  # some targets only
#
# Needs clang-14 and libclang-rt-14-dev (installed here with apt when missing). The corpus each
# target grows is kept in build/fuzz/corpus/<target> and reused by the next run.
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_SECONDS=${FUZZ_SECONDS:-60}
JOBS=${JOBS:-$(nproc)}
ALL_TARGETS="pcd pcd_ascii pcd_binary pcd_compressed ply kitti_bin lzf imu_csv calib_yaml tum kitti_poses times pointcloud2"
FUZZ_TARGETS=${FUZZ_TARGETS:-$ALL_TARGETS}
SHARED_DATA=${FARLIO_SHARED_DATA:-$(cd .. && pwd)/shared/data}
BUILD=build/fuzz
# A single input taking longer than this is a hang; more memory than this is a blow-up.
INPUT_TIMEOUT_S=10
RSS_LIMIT_MB=2048
# Inputs stay small: a reader's bugs show on a few points, and small inputs run fast.
MAX_LEN_BYTES=16384

APT_PACKAGES=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${APT_PACKAGES[@]}"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
if ((${#missing[@]})); then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "[fuzz] apt packages: ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

echo "== build ($BUILD: clang++-14, libFuzzer, ASan + UBSan) =="
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
launcher=(); command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DFARLIO_BUILD_FUZZERS=ON -DFARLIO_BUILD_TESTS=OFF -DFARLIO_BUILD_BENCHMARKS=OFF -DFARLIO_CUDA=OFF \
  -DFARLIO_SANITIZE=address,undefined "${launcher[@]}" >/dev/null
targets=(); for t in $FUZZ_TARGETS; do targets+=("fuzz_$t"); done
cmake --build "$BUILD" -j "$JOBS" --target "${targets[@]}"

shared_seeds="$BUILD/shared_seeds"
rm -rf "$shared_seeds"
if [ -d "$SHARED_DATA" ]; then
  python3 fuzz/make_seeds.py "$SHARED_DATA" "$shared_seeds"
else
  echo "[fuzz] $SHARED_DATA is absent: crafted seeds (fuzz/seeds) only"
fi

export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1" UBSAN_OPTIONS="print_stacktrace=1"
failed=()
results=()
for t in $FUZZ_TARGETS; do
  corpus="$BUILD/corpus/$t" findings="$BUILD/findings" log="$BUILD/logs/$t.log"
  mkdir -p "$corpus" "$findings" "$(dirname "$log")"
  seeds=(); for d in "fuzz/seeds/$t" "$shared_seeds/$t"; do [ -d "$d" ] && seeds+=("$d"); done
  echo "== fuzz_$t: ${FUZZ_SECONDS} s =="
  rc=0
  "$BUILD/fuzz/fuzz_$t" "$corpus" "${seeds[@]}" -max_total_time="$FUZZ_SECONDS" -timeout="$INPUT_TIMEOUT_S" \
    -rss_limit_mb="$RSS_LIMIT_MB" -max_len="$MAX_LEN_BYTES" -print_final_stats=1 \
    -artifact_prefix="$findings/$t-" >"$log" 2>&1 || rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  status=ok
  if [ "$rc" -ne 0 ]; then
    status="FAILED (exit $rc, see $log)"
    failed+=("$t")
    grep -E "ERROR|SUMMARY|runtime error|Test unit written|deadly signal" "$log" | head -5 || true
  fi
  results+=("$(printf '%-16s %12s %10s %8s  %s' "$t" "${runs:-?}" "$FUZZ_SECONDS" "${cov:-?}" "$status")")
done

echo
printf '%-16s %12s %10s %8s  %s\n' target executions seconds coverage result
printf '%s\n' "${results[@]}"
if ((${#failed[@]})); then
  echo "fuzzing found problems in: ${failed[*]} (inputs in $BUILD/findings/)" >&2
  exit 1
fi
