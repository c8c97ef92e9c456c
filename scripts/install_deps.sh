#!/usr/bin/env bash
# Installs the Debian packages the build, the tests and the demo need; does nothing when all
# are present, so it is safe to run any number of times. Usage: install_deps.sh [EXTRA_PACKAGE ...]
set -euo pipefail
packages=(
  build-essential cmake catkin ros-message-generation libroscpp-dev librosbag-dev libpcl-ros-dev
  libpcl-conversions-dev libpcl-dev libeigen3-dev libtf2-dev libtf2-ros-dev libtf2-eigen-dev libtf2-msgs-dev
  libsensor-msgs-dev libgeometry-msgs-dev libgtest-dev ros-std-msgs ros-geometry-msgs ros-sensor-msgs ros-tf2-msgs
  python3-rostest python3-rosbag python3-catkin-pkg
  libnodelet-dev libnodeletlib-dev libnodeletlib-tools libtf2-ros-dev libtf2-eigen-dev libtf2-sensor-msgs-dev
  libvisualization-msgs-dev libstd-srvs-dev libshape-msgs-dev libpcl-msgs-dev ros-pcl-msgs libdepth-image-proc-dev libdynamic-reconfigure-config-init-mutex-dev
  python3-dynamic-reconfigure libdiagnostic-updater-dev libmessage-filters-dev libpcl-conversions-dev libpng-dev libboost-program-options-dev nlohmann-json3-dev libopenni2-dev libfreenect-dev clang libclang-rt-14-dev
  ros-std-srvs ros-shape-msgs ros-visualization-msgs ros-diagnostic-msgs ros-message-runtime
  python3-roslaunch python3-rosmaster python3-rospy rosout tf2-tools rosbash
  # What a ROS user reaches for first: rostopic echo/hz, rosservice call, rosnode, rosparam, and
  # the Python bindings of every message this package's messages and topics use.
  python3-rostopic python3-rosservice python3-rosnode python3-rosparam python3-std-msgs
  python3-geometry-msgs python3-shape-msgs python3-pcl-msgs python3-sensor-msgs python3-visualization-msgs
  python3-std-srvs python3-diagnostic-msgs
)
# Extra packages a target needs beyond these (make evaluate: gnuplot-nox).
packages+=("$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing missing Debian packages: ${missing[*]}"
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
$sudo apt-get update
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${missing[@]}"
