#!/usr/bin/env bash
# Illumination invariance (Eq. 6, Illumination_invariance 1) against the grey image on real
# colour data: Gardens Point day_right vs day_left (same day), the same with the queries relit
# to a 4000 K light at 60 % intensity (build/bench/relight: a global change along the black-body
# locus, the change Eq. 6 cancels), and the Sussex panoramas (re-run vs training, 30 cm).
# Prints one Markdown row per setting. Usage: bench/illumination.sh [descriptor ...]
source "$(dirname "$0")/common.sh"
data="$datasets"
prepare "$data" "$exe" "$root/build/bench/relight" "$root/build/bench/shift_panoramas"
descriptors=("$@"); [ ${#descriptors[@]} -gt 0 ] || descriptors=(LDB HOG)
"$root/build/bench/relight" "$data/gardens_point/day_right" "$out/dusk" 6500 4000 0.6 > /dev/null
sx="$data/sussex_panoramas"
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$sx/gt_positions_training.txt" > "$out/train.csv"
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$sx/gt_positions_test_infomax_binary.txt" > "$out/rerun.csv"
"$root/build/bench/shift_panoramas" "$sx/test_infomax_binary" "$out/rerun" 0 96

figures() {  # figures SETTING...: "R@1 / AUC" of one run
  "$exe" --quiet --set Evaluation_name="$out/e" "$@" > /dev/null
  printf '%.3f / %.3f' "$(figure recall_at_1 "$out/e.json")" "$(figure auc "$out/e.json")"
}
echo "| data | descriptor | grey R@1 / AUC | Eq. 6 (alpha 0.47) R@1 / AUC |"
echo "|---|---|---|---|"
for d in "${descriptors[@]}"; do
  for q in day_right dusk; do
    qpath="$data/gardens_point/$q"; [ "$q" = dusk ] && qpath="$out/dusk"
    for L in 1 5; do
      set -- --set Images_path="$data/gardens_point/day_left" --set Images_path_2="$qpath" \
        --set Image_descriptor="$d" --set Image_sequences=$L --set Ground_truth_type=aligned \
        --set Tolerance=2
      echo "| Gardens Point day_left vs $q, L=$L, +-2 | $d | $(figures "$@" --set Illumination_invariance=0) | $(figures "$@" --set Illumination_invariance=1) |"
    done
  done
  set -- --set Images_path="$sx/training" --set Images_path_2="$out/rerun" --set Camera_type=2 \
    --set Panoramas=4 --set Panorama_matching=0 --set Image_descriptor="$d" \
    --set Ground_truth_type=positions --set Ground_truth="$out/train.csv" \
    --set Ground_truth_2="$out/rerun.csv" --set Ground_truth_radius=30 --set Tolerance=0
  echo "| Sussex re-run vs training, 4 sub-panoramas aligned, 30 cm | $d | $(figures "$@" --set Illumination_invariance=0) | $(figures "$@" --set Illumination_invariance=1) |"
done
