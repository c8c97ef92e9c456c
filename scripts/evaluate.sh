#!/usr/bin/env bash
# make evaluate: runs evaluate_paper (the paper's experiments with PCL's methods beside ours),
# then plots its data files with gnuplot into PNGs next to RESULTS.md.
# Usage: scripts/evaluate.sh BIN_DIR OUT_DIR QUICK(0|1) [FRAME.pcd ...]
# ../shared/data/osd-learn, when present beside the checkout, adds the annotated real frames.
set -euo pipefail
bin_dir=$1
out_dir=$2
quick=$3
shift 3
mkdir -p "$out_dir/results"
args=("$out_dir")
[ "$quick" = 1 ] && args+=(--quick)
osd_dir="$(dirname "$0")/../../shared/data/osd-learn"
[ -f "$osd_dir/annotations.json" ] && args+=(--osd "$osd_dir")
"$bin_dir/evaluate_paper" "${args[@]}" "$@"
gnuplot -e "dir='$out_dir/results'" "$(dirname "$0")/plot_results.gp"
echo "wrote $out_dir/RESULTS.md and its plots in $out_dir/results"
