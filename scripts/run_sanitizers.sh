#!/usr/bin/env bash
# Builds the ROS-free layers, tools and tests (core, io, sim, eval; test_core, test_io, test_sim,
# test_eval, test_tools, test_data) with plain CMake under AddressSanitizer +
# UndefinedBehaviorSanitizer and runs them with ctest. No ROS needed.
# Usage: bash scripts/run_sanitizers.sh        (build folder: <repo>/build_asan, ignored by git)
# Env:   LSF_ASAN_BUILD=<dir>, LSF_JOBS=<n> (default 2), LSF_DATA_DIR as for the tests.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${LSF_ASAN_BUILD:-$ROOT/build_asan}
export PATH=/usr/bin:/bin:$PATH
FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
DATA_ARG=()
if [ -n "${LSF_DATA_DIR:-}" ]; then DATA_ARG=("-DLSF_DATA_DIR=$LSF_DATA_DIR"); fi
cmake -S "$ROOT" -B "$BUILD" -DLSF_BUILD_ROS=OFF -DLSF_NATIVE_ARCH=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS=$FLAGS" \
  "-DCMAKE_EXE_LINKER_FLAGS=$FLAGS" "-DCMAKE_SHARED_LINKER_FLAGS=$FLAGS" "${DATA_ARG[@]}"
cmake --build "$BUILD" -j"${LSF_JOBS:-2}"
cd "$BUILD" && ASAN_OPTIONS=abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure
