#!/usr/bin/env bash
# Installs the Debian 12 packages lidar_stereo_fusion needs to build, test and run.
# Idempotent: installs only what is missing. Run as root (or with sudo available).
set -euo pipefail

PKGS=(
  build-essential cmake pkg-config python3-catkin-pkg python3-empy catkin
  ros-base-dev libnodeletlib-dev pluginlib-dev
  libpcl-ros-dev libpcl-conversions-dev libpcl-dev libpcl-ros-filters0d pcl-tools
  libcv-bridge-dev libimage-transport-dev libimage-geometry-dev
  libtf2-ros-dev libtf2-eigen-dev libtf2-sensor-msgs-dev
  libmessage-filters-dev librosbag-dev python3-rosbag
  librostest-dev python3-rostest
  libstereo-msgs-dev ros-stereo-msgs libdiagnostic-updater-dev python3-diagnostic-msgs
  libdepth-image-proc0d libdepth-image-proc-dev ros-stereo-image-proc libstereo-image-proc-dev
  python3-dynamic-reconfigure libdynamic-reconfigure-config-init-mutex-dev
  libgtest-dev libopencv-dev libeigen3-dev libyaml-cpp-dev
  python3-roslaunch ros-message-generation ros-message-runtime
  xvfb imagemagick rviz rosbash python3-sensor-msgs python3-stereo-msgs
  clang libclang-rt-14-dev libomp-dev clang-format-14
  python3-distributed python3-dask python3-psutil python3-pytest
)

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PKGS[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install_deps: installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
