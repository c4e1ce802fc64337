#!/usr/bin/env bash
# The README demo. Installs the Debian dependencies (scripts/install_deps.sh; skip with
# LSF_SKIP_DEPS=1), builds the ROS-free core and tools with plain CMake into build_demo/ (an
# existing build is reused and only brought up to date), then runs lsf_demo with the arguments:
#
#   scripts/demo.sh                 synthetic street with exact ground truth -> ./demo_output
#   scripts/demo.sh --fast          the same at half size (620x188), a quick look
#   scripts/demo.sh --kitti         the KITTI sample in ../shared/data, scored on held-out rings
#   scripts/demo.sh --generate DIR  write the synthetic street in the KITTI raw layout
#   scripts/demo.sh --help          all options
#
# In a built catkin workspace of this clone (its devel/setup.bash sourced), the workspace's
# lsf_demo (`rosrun lidar_stereo_fusion lsf_demo`) runs as is, with no build.
#
# Environment: LSF_DEMO_BUILD_DIR (default <repo>/build_demo), LSF_JOBS (default: all cores),
#              LSF_DEMO_REBUILD=1 (build build_demo/ even when a workspace has lsf_demo).
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LSF_DEMO_BUILD_DIR:-$repo/build_demo}"
jobs="${LSF_JOBS:-$(nproc)}"

if [ "${LSF_SKIP_DEPS:-0}" != "1" ]; then
  "$repo/scripts/install_deps.sh"
fi
# A sourced catkin workspace built from this clone already has lsf_demo.
if [ "${LSF_DEMO_REBUILD:-0}" != "1" ] && [ -x /usr/bin/catkin_find ] && [ -x /usr/bin/rospack ]; then
  pkg_dir=$(PATH=/usr/bin:/bin:$PATH rospack find lidar_stereo_fusion 2>/dev/null || true)
  ws_demo=$(PATH=/usr/bin:/bin:$PATH catkin_find --first-only --libexec lidar_stereo_fusion lsf_demo \
            2>/dev/null | head -n 1 || true)
  if [ -n "$pkg_dir" ] && [ "$(realpath "$pkg_dir")" = "$(realpath "$repo")" ] && [ -x "$ws_demo" ]; then
    echo "demo: using the workspace's $ws_demo (rosrun lidar_stereo_fusion lsf_demo; LSF_DEMO_REBUILD=1 builds $build instead)"
    exec "$ws_demo" "$@"
  fi
fi

if [ ! -f "$build/CMakeCache.txt" ]; then
  echo "demo: configuring $build (plain CMake, no ROS)"
  cmake -S "$repo" -B "$build" -DLSF_BUILD_ROS=OFF -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
echo "demo: building lsf_demo in $build"
cmake --build "$build" --target lsf_demo -j "$jobs" >/dev/null
exec "$build/lsf_demo" "$@"
