#!/usr/bin/env bash
# make demo: the simulated Kinect and the detector nodelet under roslaunch for about 20 s, then
# the map against the true planes and a picture. The launch's own log goes to a file.
set -eo pipefail  # not -u: /etc/catkin/profile.d reads unset variables
ws="$1"
seconds="${2:-20}"
picture="${3:-$PWD/build/demo.png}"
source "$ws/devel/setup.bash"
log="$PWD/build/demo_launch.log"
roslaunch hough_plane_detector demo.launch > "$log" 2>&1 &
launch_pid=$!
trap 'kill -INT $launch_pid 2>/dev/null; wait $launch_pid 2>/dev/null || true' EXIT
sleep 3  # let roslaunch bring up its master first
echo "demo.launch running (log: $log); watching the detector for $seconds s ..."
"$ws/devel/lib/hough_plane_detector/plane_report" _duration:="$seconds" _picture:="$picture" __name:=plane_report
