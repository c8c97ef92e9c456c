#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang with ASan and UBSan) and runs each from seeds.
#   run_fuzzers.sh smoke RESULTS_DIR   a fixed number of runs with a fixed seed: repeatable, for make test
#   run_fuzzers.sh long SECONDS        as long as asked per target, for make fuzz
# A crash leaves its input in build/fuzz/crash-*; turn it into a regression test.
set -euo pipefail
mode="$1"
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/build/fuzz"
cmake -S "$root/fuzz" -B "$out" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE= > "$out.configure.log" 2>&1 \
  || { cat "$out.configure.log"; exit 1; }
cmake --build "$out" -j2 > "$out.build.log" 2>&1 || { tail -30 "$out.build.log"; exit 1; }
mkdir -p "$out/corpus_map" "$out/corpus_cloud" "$out/corpus_pcd_header"
"$out/make_seed_map" "$out/corpus_map/seed.map" "$out/corpus_cloud/seed.cloud"
printf '# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n0 0 1\n0 0 1\n' \
  > "$out/corpus_pcd_header/seed.pcd"
status=0
for target in fuzz_cloud_view fuzz_map_file fuzz_pcd_header; do
  corpus="$out/corpus_${target#fuzz_}"
  corpus="${corpus/corpus_cloud_view/corpus_cloud}"
  corpus="${corpus/corpus_map_file/corpus_map}"
  if [ "$mode" = smoke ]; then
    # Map inputs are 250 kB: fewer runs keep the smoke test near ten seconds per target.
    args=(-seed=1 -runs=$([ "$target" = fuzz_map_file ] && echo 4000 || echo 30000))
  else
    args=(-max_total_time="$2")
  fi
  start=$(date +%s)
  if (cd "$out" && "./$target" "${args[@]}" -rss_limit_mb=2048 "$corpus" > "$out/$target.log" 2>&1); then
    result=""
    echo "fuzz $target: ok ($(grep -oE 'Done [0-9]+ runs' "$out/$target.log"))"
  else
    status=1
    result="<failure message=\"$target crashed; see build/fuzz/$target.log\"/>"
    echo "fuzz $target: FAILED"; grep -E "ERROR|SUMMARY" "$out/$target.log" | head -5
  fi
  if [ "$mode" = smoke ]; then
    mkdir -p "$2"
    elapsed=$(($(date +%s) - start))
    printf '<?xml version="1.0"?>\n<testsuite name="fuzz" tests="1" failures="%d"><testcase classname="fuzz" name="%s" time="%s">%s</testcase></testsuite>\n' \
      "$([ -n "$result" ] && echo 1 || echo 0)" "$target" "$elapsed" "$result" > "$2/fuzz-$target.xml"
  fi
done
exit $status
