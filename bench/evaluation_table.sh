#!/usr/bin/env bash
# The table of docs/benchmarks.md: every descriptor on KITTI 00 (frames 0-1699), Nordland
# (winter vs summer) and Gardens Point (day_right vs day_left), with the protocols of
# docs/benchmarks.md ("Accuracy"), evaluated by Test_OpenABLE itself. Prints one Markdown row per run.
# Usage: bench/evaluation_table.sh [descriptor ...]   (default: LDB ORB BRISK SIFT HOG BRIEF FREAK)
source "$(dirname "$0")/common.sh"
data="$datasets"
prepare "$data" "$exe"
descriptors=("$@")
[ ${#descriptors[@]} -gt 0 ] || descriptors=(LDB ORB BRISK SIFT HOG BRIEF FREAK)

run() {  # run NAME SETTING... : one row
  local name=$1; shift
  local start end
  start=$(date +%s.%N)
  "$exe" --quiet --set Evaluation_name="$out/e" "$@" > "$out/report"
  end=$(date +%s.%N)
  printf '| %s | %s | %.3f | %.3f | %.3f | %.3f | %.1f | %.1f s |\n' "$name" "$d" \
    "$(figure recall_at_1 "$out/e.json")" "$(figure auc "$out/e.json")" \
    "$(figure recall_at_100p "$out/e.json")" "$(figure max_f1 "$out/e.json")" \
    "$(figure average_precision_percent "$out/e.json")" "$(awk -v a="$start" -v b="$end" 'BEGIN{print b-a}')"
}

echo "| data | descriptor | R@1 | AUC | R@100P | max F1 | ABLE-P AP | wall time |"
echo "|---|---|---|---|---|---|---|---|"
for d in "${descriptors[@]}"; do
  run "KITTI 00 0-1699, L=1, +-3, excl. 100, heading < 45" \
    --set Images_path="$data/kitti00_first1700/image_0" --set Image_descriptor="$d" \
    --set Image_sequences=1 --set Ground_truth_type=kitti \
    --set Ground_truth="$data/kitti00_first1700/poses/00_first1700.txt" \
    --set Ground_truth_axes=xz --set Ground_truth_heading=45 --set Exclusion=100 --set Tolerance=3
  for L in 1 10; do
    run "Nordland winter vs summer, L=$L, +-2" \
      --set Images_path="$data/nordland_trimmed/summer" \
      --set Images_path_2="$data/nordland_trimmed/winter" --set Image_descriptor="$d" \
      --set Image_sequences=$L --set Ground_truth_type=aligned --set Tolerance=2
  done
  run "Gardens Point day_right vs day_left, L=5, +-2" \
    --set Images_path="$data/gardens_point/day_left" \
    --set Images_path_2="$data/gardens_point/day_right" --set Image_descriptor="$d" \
    --set Image_sequences=5 --set Ground_truth_type=aligned --set Tolerance=2
done
