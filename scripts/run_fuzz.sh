#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (ASan + UBSan) and runs each for a bounded time
# on its seed corpus; fails on the first crash, sanitizer report, leak or timeout.
# Usage: bash scripts/run_fuzz.sh <seed dir> [seconds per target]
#   <seed dir>: the fuzz_seeds/ folder the tests write (<catkin build>/lidar_stereo_fusion/fuzz_seeds)
# Env: LSF_FUZZ_BUILD=<dir> build folder (default: <repo>/build_fuzz, ignored by git)
#      LSF_JOBS=<n>         parallel compile jobs (default 2)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SEEDS=${1:?usage: run_fuzz.sh <seed dir> [seconds]}
SECONDS_PER_TARGET=${2:-20}
BUILD=${LSF_FUZZ_BUILD:-$ROOT/build_fuzz}
JOBS=${LSF_JOBS:-2}
export PATH=/usr/bin:/bin:$PATH

echo "== fuzz: build ($BUILD)"
CC=clang CXX=clang++ cmake -S "$ROOT/fuzz" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
cmake --build "$BUILD" -j"$JOBS"

# -seed=1: a run explores the same inputs as any other run of the same length (a finding can be
# reproduced by re-running the script), instead of a new random walk each time.
status=0
for target in pointcloud2 image kitti_calib kitti_bin autoware_calib params_yaml pcd; do
  seeds="$SEEDS/$target"
  if [ ! -d "$seeds" ] || [ -z "$(ls -A "$seeds")" ]; then
    echo "fuzz_$target: no seed corpus in $seeds (run the tests first)" >&2
    status=1
    continue
  fi
  corpus="$BUILD/corpus/$target"
  mkdir -p "$corpus" "$BUILD/artifacts"
  echo "== fuzz_$target: ${SECONDS_PER_TARGET} s from $(ls "$seeds" | wc -l) seeds"
  if ! (cd "$BUILD" && "./fuzz_$target" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -seed=1 \
        -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1 \
        -artifact_prefix="$BUILD/artifacts/${target}-" "$corpus" "$seeds" > "$BUILD/$target.log" 2>&1); then
    echo "fuzz_$target FAILED (reproducer in $BUILD/artifacts/):" >&2
    grep -E "ERROR|SUMMARY|runtime error|terminate|==[0-9]+==" "$BUILD/$target.log" | head -20 >&2 || true
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$BUILD/$target.log" | tail -2 || true
  fi
done
[ $status -eq 0 ] && echo "fuzz: every target ran ${SECONDS_PER_TARGET} s without a finding"
exit $status
