#!/usr/bin/env bash
# The nodelet soak of make soak: FRAMES clouds through the detector nodelet while soak_monitor
# prints the manager's resident memory; then a short run of the manager under valgrind, whose
# definitely-lost blocks that pass through this package's code are counted. In a workspace
# built with AddressSanitizer (make soak SANITIZE=address) the short run is under LeakSanitizer
# instead (valgrind cannot run ASan code), and the memory run is left to the plain build.
# Usage: scripts/soak_nodelet.sh WORKSPACE FRAMES LEAK_CHECK_FRAMES (LEAK_EXPECTED=1: a leak must be found)
set -uo pipefail
ws=$1
frames=$2
leak_check_frames=$3
here=$(cd "$(dirname "$0")/.." && pwd)
set +u
source "$ws/devel/setup.bash"
set -u
launch=$here/bench/soak_nodelet.launch
monitor=$ws/devel/lib/hough_plane_detector/soak_monitor
port=$((11400 + RANDOM % 500))
export ROS_MASTER_URI=http://localhost:$port

run() {  # run LOG FRAMES RATE PREFIX BOND
  roslaunch -p "$port" "$launch" rate:="$3" manager_prefix:="$4" bond:="$5" > "$1" 2>&1 &
  local launch_pid=$!
  local manager=""
  for _ in $(seq 1 100); do
    manager=$(pgrep -n -f "manager __name:=soak_manager")
    [ -n "$manager" ] && break
    sleep 0.2
  done
  "$monitor" _manager_pid:="${manager:-0}" _frames:="$2"
  local status=$?
  kill -INT "$launch_pid"
  wait "$launch_pid"
  return $status
}

# Leak records (blank-line separated) whose allocation stack passes through this package.
count_ours() {
  awk -v start="$2" '$0 ~ start {block=1; text=""} block {text=text $0 "\n"} /^(==[0-9]+== )?$/ {if (block && text ~ /hough_plane_detector/) n++; block=0} END {print n+0}' "$1"
}

nodelets=$ws/devel/lib/libhough_plane_detector_nodelets.so
if ldd "$nodelets" | grep -q libasan; then
  echo "== $leak_check_frames frames at 20 Hz with the manager under LeakSanitizer (the memory run is for the plain build)"
  preload=$(gcc -print-file-name=libasan.so)
  if ldd "$nodelets" | grep -q libubsan; then preload="$preload $(gcc -print-file-name=libubsan.so)"; fi
  rm -f "$ws"/soak_lsan.*
  run "$ws/soak_nodelet_lsan.log" "$leak_check_frames" 20 \
    "env LD_PRELOAD='$preload' ASAN_OPTIONS=detect_leaks=1:atexit=1:verify_asan_link_order=0:log_path=$ws/soak_lsan" \
    --no-bond > /dev/null || { echo "LeakSanitizer run failed: see $ws/soak_nodelet_lsan.log"; exit 1; }
  # atexit=1 writes ASan's exit statistics, a found leak ends the process before them with
  # LeakSanitizer's report: without either the manager never reached its exit (killed), and
  # LeakSanitizer, which runs there, did not check anything.
  log=$(ls "$ws"/soak_lsan.* 2>/dev/null | head -1)
  if [ -z "$log" ] || ! grep -qE "Stats:|ERROR: LeakSanitizer" "$log"; then
    echo "the manager did not exit normally, so LeakSanitizer did not run: see $ws/soak_nodelet_lsan.log"
    exit 1
  fi
  grep -E "^SUMMARY" "$log" || echo "LeakSanitizer: no leak in the manager ($log)"
  ours=$(count_ours "$log" "(Direct|Indirect) leak of")
  echo "leak records through hough_plane_detector code: $ours (full log: $log)"
  # LEAK_EXPECTED=1 (make soak-control): the build leaks on purpose and must be caught.
  if [ "${LEAK_EXPECTED:-0}" = 1 ]; then [ "$ours" -gt 0 ]; else [ "$ours" = 0 ]; fi
  exit
fi

echo "== $frames frames through the nodelet (simulated Kinect replaying a lap at 50 Hz)"
run "$ws/soak_nodelet.log" "$frames" 50 "" "" || { echo "soak run failed: see $ws/soak_nodelet.log"; exit 1; }

echo "== $leak_check_frames frames with the manager under valgrind --leak-check=full"
vlog=$ws/soak_valgrind.%p.log
rm -f "$ws"/soak_valgrind.*.log
run "$ws/soak_nodelet_valgrind.log" "$leak_check_frames" 5 "valgrind --leak-check=full --num-callers=30 --log-file=$vlog" \
  --no-bond > /dev/null || { echo "valgrind run failed: see $ws/soak_nodelet_valgrind.log"; exit 1; }
log=$(ls "$ws"/soak_valgrind.*.log | head -1)
grep -E "definitely lost:|ERROR SUMMARY" "$log"
ours=$(count_ours "$log" "definitely lost in loss record")
echo "definitely-lost records through hough_plane_detector code: $ours (full log: $log)"
[ "$ours" = 0 ]
