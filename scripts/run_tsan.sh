#!/usr/bin/env bash
# The ThreadSanitizer run of make tsan / make tsan-control: test/concurrency.test for SECONDS
# with the nodelet manager preloading libtsan; reports go to WORKSPACE/tsan.manager.*.
# EXPECT=clean passes when the manager has no report; EXPECT=reported (the negative control,
# built with test/negative_controls/map_lock_skipped.cpp: the map is never locked) passes
# only when a race through saveMapService is reported.
# Usage: scripts/run_tsan.sh WORKSPACE SECONDS clean|reported
set -uo pipefail
ws=$1
seconds=$2
expect=$3
here=$(cd "$(dirname "$0")/.." && pwd)
catkin_make -C "$ws" tests > "$ws/build_tests.log" 2>&1 || { tail -30 "$ws/build_tests.log"; exit 1; }
rm -f "$ws"/tsan.*
set +u
source "$ws/devel/setup.bash"
set -u
supp=$here/scripts/tsan.supp
HOUGH_PLANE_DETECTOR_STRESS_SECONDS=$seconds \
  HOUGH_PLANE_DETECTOR_MANAGER_PREFIX="env LD_PRELOAD=$(gcc -print-file-name=libtsan.so) TSAN_OPTIONS=log_path=$ws/tsan.manager:history_size=4:suppressions=$supp" \
  TSAN_OPTIONS=log_path=$ws/tsan.client:suppressions=$supp \
  rostest --text hough_plane_detector concurrency.test > "$ws/tsan_rostest.log" 2>&1
grep -E "^\[ *(OK|FAILED) *\]|rounds|Failure" "$ws/tsan_rostest.log"
reports=$(cat "$ws"/tsan.manager.* 2>/dev/null | grep -c "WARNING: ThreadSanitizer")
echo "ThreadSanitizer reports in the nodelet manager: $reports ($ws/tsan.manager.*; the test client's own, in roscpp, are in tsan.client.*)"
if [ "$expect" = clean ]; then
  # A run whose test did not pass proves nothing, reports or not.
  grep -qE "^\[ *OK *\] Concurrency" "$ws/tsan_rostest.log" || { echo "concurrency.test did not pass: $ws/tsan_rostest.log"; exit 1; }
  [ "$reports" = 0 ]
  exit
fi
# TSan cannot name frames of the nodelet library here, so find saveMapService by address.
library=$ws/devel/lib/libhough_plane_detector_nodelets.so
through_save=0
for offset in $(cat "$ws"/tsan.manager.* 2>/dev/null | grep -o "libhough_plane_detector_nodelets.so+0x[0-9a-f]*" | sed 's/.*+//' | sort -u); do
  if addr2line -f -C -i -e "$library" "$offset" | grep -q "saveMapService"; then through_save=$((through_save + 1)); fi
done
echo "negative control: stack frames in saveMapService among the reports: $through_save"
[ "$through_save" -gt 0 ]
