#!/usr/bin/env bash
# catkin_make install, then test/install_space.test with nothing but the install space (and
# /usr's ROS) on the package path: what the install rules leave out fails here.
# usage: test_install_space.sh <workspace> <results dir>
set -euo pipefail
ws=$1
results=$2
test_file=$(cd "$(dirname "$0")/.." && pwd)/test/install_space.test
mkdir -p "$results"
rm -f "$results/install_space_failed.xml"
# A failure before rostest writes its results still counts in test_summary.py.
fail() {
  printf '<testsuite name="install_space" tests="1"><testcase classname="install_space" name="%s"><failure message="%s"/></testcase></testsuite>\n' \
    "$1" "$1: see $2" > "$results/install_space_failed.xml"
  tail -30 "$2"
  exit 1
}
catkin_make -C "$ws" install > "$ws/install.log" 2>&1 || fail catkin_make_install "$ws/install.log"
# A clean environment: the devel space (and any sourced workspace) must not leak in.
env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 bash -c '
  source "$1/install/setup.bash"
  case "$(rospack find hough_plane_detector)" in
    "$1/install/"*) ;;
    *) echo "install space test: hough_plane_detector resolves outside $1/install"; exit 1;;
  esac
  ROS_HOME="$2/ros_home" rostest --results-base-dir="$2" "$3"' _ "$ws" "$results" "$test_file" \
  > "$ws/install_space_test.log" 2>&1 || fail rostest_from_the_install_space "$ws/install_space_test.log"
