#!/usr/bin/env bash
# make test SANITIZE=...: the gtest binaries once more, alone, with LeakSanitizer on (the ROS
# test run keeps it off because the preloaded runtime would also watch Python). Results go
# next to the others as JUnit files, so a sanitizer report fails the summary.
set -uo pipefail
ws="$1"
results="$ws/build/test_results/sanitized"
mkdir -p "$results"
for binary in test_core test_detect_planes_cli; do
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$ws/devel/lib/hough_plane_detector/$binary" --gtest_output="xml:$results/$binary.xml" > "$results/$binary.log" 2>&1
  code=$?
  if grep -qE "ERROR: (AddressSanitizer|LeakSanitizer)|runtime error" "$results/$binary.log" || [ $code -ne 0 ]; then
    echo "sanitized $binary: FAILED (exit $code); see $results/$binary.log"
    grep -E "ERROR: |runtime error|SUMMARY" "$results/$binary.log" | head -5
    printf '<?xml version="1.0"?>\n<testsuite name="sanitizers" tests="1" failures="1"><testcase classname="sanitizers" name="%s"><failure message="sanitizer report or exit %s"/></testcase></testsuite>\n' \
      "$binary" "$code" > "$results/$binary-sanitizer.xml"
  else
    echo "sanitized $binary: clean"
  fi
done
