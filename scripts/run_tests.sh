#!/usr/bin/env bash
# Installs what is missing, checks the C++ formatting (scripts/check_format.sh: clang-format 14 and
# .clang-format; a diff fails the run after the tests), builds the package in a catkin workspace
# and runs every test: core gtests (exact synthetic answers), data gtests (../shared/data), rostests (node, nodelet,
# calibration, KITTI bag playback at several rates, RViz), the launch-file check, and then each
# libFuzzer target of fuzz/ for a bounded time (scripts/run_fuzz.sh).
# Usage: bash scripts/run_tests.sh            (from anywhere; the workspace goes to ./ws)
# Env:   LSF_WS=<dir>       catkin workspace to use (default: <repo>/ws, ignored by git)
#        LSF_DATA_DIR=<dir> the shared real data (default: <repo>/../shared/data)
#        CI=true            data tests fail instead of skipping when the data is missing
#        LSF_FUZZ_SECONDS=N each libFuzzer target runs N s after the tests (default 20; 0 = skip)
#        LSF_FUZZ_BUILD=<dir> build folder of the fuzz targets (default: <workspace>/build_fuzz)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
WS=${LSF_WS:-$ROOT/ws}
DATA=${LSF_DATA_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}
JOBS=${LSF_JOBS:-2}

# Where the time goes: each phase's wall time, printed at the end (doc/tools.md has a table).
PHASES=()
phase_start=$SECONDS
phase_done() {
  PHASES+=("$(printf '%6d s  %s' $((SECONDS - phase_start)) "$1")")
  phase_start=$SECONDS
}
print_phases() {
  echo "== time per phase"
  printf '%s\n' "${PHASES[@]}"
  printf '%6d s  total\n' "$SECONDS"
}

bash "$ROOT/scripts/install_deps.sh"
phase_done "install (scripts/install_deps.sh)"

echo "== format (clang-format 14, .clang-format)"
format_status=0
bash "$ROOT/scripts/check_format.sh" || format_status=$?
echo "== docs (doc/method.md names existing files and functions)"
docs_status=0
bash "$ROOT/scripts/check_docs.sh" || docs_status=$?
phase_done "format and docs checks"

# Debian's ROS uses the system Python; a pyenv python3 first on PATH breaks catkin.
export PATH=/usr/bin:/bin:$PATH
export ROS_HOME=${ROS_HOME:-$WS/ros_home}
export ROS_LOG_DIR=${ROS_LOG_DIR:-$WS/ros_home/log}

# The package in the workspace is a folder of links to the repository's top-level entries, not a
# link to the repository itself: with the workspace inside the repository (the default), such a
# link is a loop, and tools that walk the package folder (roslaunch looking for playback.launch)
# find the file again under ws/src/lidar_stereo_fusion/ws/src/... and refuse it as ambiguous.
PKG="$WS/src/lidar_stereo_fusion"
mkdir -p "$WS/src"
if [ -L "$PKG" ]; then rm "$PKG"; fi
mkdir -p "$PKG"
for entry in "$ROOT"/* "$ROOT"/.[!.]*; do
  [ -e "$entry" ] || continue
  name=$(basename "$entry")
  if [ "$name" = .git ] || [ "$entry" -ef "$WS" ]; then continue; fi
  ln -sfn "$entry" "$PKG/$name"
done
for link in "$PKG"/* "$PKG"/.[!.]*; do  # entries removed from the repository
  if [ -L "$link" ] && [ ! -e "$link" ]; then rm "$link"; fi
done
cd "$WS"
# Both Python variables: Debian's pluginlib looks Python up again with find_package(Python3).
CMAKE_ARGS=(-DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3
            -DCMAKE_BUILD_TYPE=Release "-DLSF_DATA_DIR=$DATA")

echo "== build (catkin workspace $WS)"
catkin_make "${CMAKE_ARGS[@]}" -j"$JOBS" all
phase_done "build: catkin_make all"
# `run_tests` builds only the test targets, so `all` comes first.
rm -rf "$WS/build/test_results"
echo "== build the tests"
set +eu  # catkin's setup scripts read unset variables
# shellcheck disable=SC1091
source "$WS/devel/setup.bash"
catkin_make "${CMAKE_ARGS[@]}" -j"$JOBS" tests
build_tests_status=$?
phase_done "build: catkin_make tests (test binaries, rostest nodes)"
echo "== tests"
catkin_make "${CMAKE_ARGS[@]}" -j"$JOBS" run_tests
run_status=$?
if [ $build_tests_status -ne 0 ]; then run_status=$build_tests_status; fi
phase_done "tests: catkin_make run_tests"
set -e

summary_status=0
python3 "$ROOT/scripts/summarize_test_results.py" "$WS/build/test_results" || summary_status=$?

# libFuzzer targets (fuzz/), each for a bounded time on the seeds the tests just wrote.
fuzz_status=0
if [ "${LSF_FUZZ_SECONDS:-20}" != "0" ]; then
  LSF_FUZZ_BUILD=${LSF_FUZZ_BUILD:-$WS/build_fuzz} bash "$ROOT/scripts/run_fuzz.sh" \
    "$WS/build/lidar_stereo_fusion/fuzz_seeds" "${LSF_FUZZ_SECONDS:-20}" || fuzz_status=$?
  phase_done "fuzz: build (clang, ASan + UBSan) and ${LSF_FUZZ_SECONDS:-20} s per target"
fi
print_phases

if [ $run_status -ne 0 ]; then
  echo "run_tests exited with $run_status" >&2
  exit $run_status
fi
if [ $fuzz_status -ne 0 ]; then
  echo "fuzzing found a problem (see above)" >&2
  exit $fuzz_status
fi
if [ $format_status -ne 0 ]; then
  echo "C++ sources differ from clang-format's format (see '== format' above)" >&2
  exit $format_status
fi
if [ $docs_status -ne 0 ]; then
  echo "doc/method.md names a file or function that does not exist (see '== docs' above)" >&2
  exit $docs_status
fi
exit $summary_status
