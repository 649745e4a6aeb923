#!/usr/bin/env bash
# The panorama benchmark on the real Sussex panoramas (../shared/datasets/sussex_panoramas):
# the 96 tracked frames of the re-run (test_infomax_binary, same direction) as queries against
# the 455 frames of the training route; a query's true places are the training frames within
# 30 cm of it (tracked positions, Ground_truth_type positions, Tolerance 0). R@1 = share of
# queries whose best match is a true place. Each setting is run on the unshifted re-run and on
# the re-run with every panorama circularly shifted by half its width (the robot facing the
# other way). Usage: bench/sussex_panoramas.sh [descriptor ...] (default LDB HOG)
source "$(dirname "$0")/common.sh"
data="$datasets/sussex_panoramas"
shift_tool="$root/build/bench/shift_panoramas"
prepare "$data" "$exe" "$shift_tool"
descriptors=("$@"); [ ${#descriptors[@]} -gt 0 ] || descriptors=(LDB HOG)

"$shift_tool" "$data/test_infomax_binary" "$out/rerun" 0 96
"$shift_tool" "$data/test_infomax_binary" "$out/rerun_half" 0.5 96
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$data/gt_positions_training.txt" > "$out/train.csv"
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$data/gt_positions_test_infomax_binary.txt" \
  | head -96 > "$out/rerun.csv"

r1() {  # r1 QUERIES SETTING...: R@1 of one run
  local q=$1; shift
  "$exe" --quiet --set Images_path="$data/training" --set Images_path_2="$q" \
    --set Ground_truth_type=positions --set Ground_truth="$out/train.csv" \
    --set Ground_truth_2="$out/rerun.csv" --set Ground_truth_radius=30 --set Tolerance=0 \
    --set Evaluation_name="$out/e" "$@" > /dev/null
  printf '%.3f' "$(figure recall_at_1 "$out/e.json")"
}

echo "| descriptor | Panoramas | aligned, unshifted | aligned, half-turn | cross-correlation, half-turn | circular, half-turn | cross-correlation, unshifted | circular, unshifted |"
echo "|---|---|---|---|---|---|---|---|"
for d in "${descriptors[@]}"; do
  for p in 2 4 6 8; do
    common=(--set Camera_type=2 --set Panoramas="$p" --set Image_descriptor="$d")
    printf '| %s | %d | %s | %s | %s | %s | %s | %s |\n' "$d" "$p" \
      "$(r1 "$out/rerun" "${common[@]}" --set Panorama_matching=0)" \
      "$(r1 "$out/rerun_half" "${common[@]}" --set Panorama_matching=0)" \
      "$(r1 "$out/rerun_half" "${common[@]}" --set Panorama_matching=1)" \
      "$(r1 "$out/rerun_half" "${common[@]}" --set Panorama_matching=2)" \
      "$(r1 "$out/rerun" "${common[@]}" --set Panorama_matching=1)" \
      "$(r1 "$out/rerun" "${common[@]}" --set Panorama_matching=2)"
  done
done
