#!/usr/bin/env bash
# DenseVLAD against HOG and SIFT where the viewpoint and the light change together: Gardens
# Point day_right against day_left (the other side of the path) and night-like variants of
# day_right (build/bench/make_night, as bench/auto.sh makes them) against day_left, at L = 1, 10
# and 40, with the auto preset's matching (ratio score <= 0.9, confirmed by one independent
# query) and Auto 0; the same on the other shared pairs (Nordland, KITTI 00, the RTAB-Map
# sample, the Sussex panoramas). Then the auto mode with and without DenseVLAD among its
# candidates on the pairs of bench/auto.sh. Prints Markdown rows (docs/benchmarks.md, "A descriptor for viewpoint and light
# together"). Usage: bench/viewpoint_light.sh [work folder] (default: a temporary folder).
source "$(dirname "$0")/common.sh"
need_data "$datasets/gardens_point"
need_built "$exe" "$root/build/bench/make_night" "$root/build/bench/shift_panoramas"
if [ $# -ge 1 ]; then work="$1"; mkdir -p "$work"; else temp_out; work="$out"; fi
source "$(dirname "$0")/shared_pairs.sh"

aligned=(--set Ground_truth_type=aligned --set Tolerance=2)
common=(--quiet --json --set Npy_name= --set Png_name= --set Evaluation_name=)

echo "| pair | descriptor | L | R@1 | AUC | R@100P | accepted | precision | describing, s |"
echo "|---|---|---|---|---|---|---|---|---|"
for p in "day_right vs day_left|$gp/day_right" "night-like day_right vs day_left|$night/gp_right_night" \
         "strong night-like day_right vs day_left|$night/gp_right_night_strong" \
         "extreme night-like day_right vs day_left|$night/gp_right_night_extreme"; do
  IFS='|' read -r name query <<< "$p"
  for d in HOG SIFT DenseVLAD; do
    for L in 1 10 40; do
      "$exe" "$root/config/presets/auto.txt" --set Auto=0 "${common[@]}" "${aligned[@]}" \
        --set Images_path="$gp/day_left" --set Images_path_2="$query" \
        --set Image_descriptor=$d --set Image_sequences=$L > "$work/run.json"
      seconds="$(python3 -c "import json,sys; print('%.1f' % json.load(open(sys.argv[1]))['timings']['description'])" "$work/run.json")"
      IFS='|' read -r r1 auc r100 acc prec _ <<< "$(figures "$work/run.json")"
      echo "| $name | $d | $L | $r1 | $auc | $r100 | $acc | $prec | $seconds |"
    done
  done
done

echo
echo "| pair | descriptor | L | R@1 | AUC | R@100P | accepted | precision |"
echo "|---|---|---|---|---|---|---|---|"
for p in "Nordland winter vs summer|$nl/summer|$nl/winter|aligned" \
         "KITTI 00 1500-1699 vs 40-260|$work/parts/kitti_ref|$work/parts/kitti_qry|kitti" \
         "RTAB-Map sample, lap 2 vs lap 1|$work/parts/rtab_lap1|$work/parts/rtab_lap2|rtab" \
         "Sussex panoramas, re-run vs training|$sx/training|$work/sussex_rerun|sussex"; do
  IFS='|' read -r name ref query kind <<< "$p"
  # shellcheck disable=SC2046
  gt=($(truth "$kind"))
  for d in HOG SIFT DenseVLAD; do
    for L in 1 10 40; do
      "$exe" "$root/config/presets/auto.txt" --set Auto=0 "${common[@]}" "${gt[@]}" \
        --set Images_path="$ref" --set Images_path_2="$query" \
        --set Image_descriptor=$d --set Image_sequences=$L > "$work/run.json"
      IFS='|' read -r r1 auc r100 acc prec _ <<< "$(figures "$work/run.json")"
      echo "| $name | $d | $L | $r1 | $auc | $r100 | $acc | $prec |"
    done
  done
done

echo
echo "| pair | without DenseVLAD: R@1 / AUC / accepted (precision) / chosen | with DenseVLAD: R@1 / AUC / accepted (precision) / chosen |"
echo "|---|---|---|"
default="Image_descriptor=HOG,SIFT,LDB,HOG+LDB Image_sequences=10,20,40 | Image_descriptor=SAD Contrast_enhancement=1 Image_sequences=10,20,40"
pairs=(
  "Gardens Point day_right vs day_left|$gp/day_left|$gp/day_right|aligned"
  "Gardens Point day_left vs day_right|$gp/day_right|$gp/day_left|aligned"
  "*GP night-like day_right vs day_left|$gp/day_left|$night/gp_right_night|aligned"
  "*GP strong night-like day_right vs day_left|$gp/day_left|$night/gp_right_night_strong|aligned"
  "*GP extreme night-like day_right vs day_left|$gp/day_left|$night/gp_right_night_extreme|aligned"
  "Nordland winter vs summer|$nl/summer|$nl/winter|aligned"
  "Nordland 0-299, winter vs summer|$work/parts/nord_s0|$work/parts/nord_w0|aligned"
  "Nordland 600-899, summer vs winter|$work/parts/nord_w600|$work/parts/nord_s600|aligned"
  "Nordland 1200-1499, winter vs summer|$work/parts/nord_s1200|$work/parts/nord_w1200|aligned"
  "*GP night-like day_right vs day_right|$gp/day_right|$night/gp_right_night|aligned"
  "*Nordland night-like summer vs summer|$nl/summer|$night/nord_summer_night|aligned"
  "*Nordland night-like winter vs summer|$nl/summer|$night/nord_winter_night|aligned"
  "*Nordland strong night-like summer vs winter|$nl/winter|$night/nord_summer_night_strong|aligned"
  "*Nordland extreme night-like winter vs summer|$nl/summer|$night/nord_winter_night_extreme|aligned"
  "Sussex panoramas, re-run vs training|$sx/training|$work/sussex_rerun|sussex"
  "RTAB-Map sample, lap 2 vs lap 1|$work/parts/rtab_lap1|$work/parts/rtab_lap2|rtab"
  "KITTI 00 1500-1699 vs 40-260|$work/parts/kitti_ref|$work/parts/kitti_qry|kitti"
  "Unrelated: Nordland winter 1100-1299 vs Gardens Point|$gp/day_left|$work/parts/nord_winter_c|none"
  "Unrelated: Nordland winter 1100-1699 vs summer 0-599|$work/parts/nord_summer_a|$work/parts/nord_winter_b|none"
)
for p in "${pairs[@]}"; do
  IFS='|' read -r name ref query kind <<< "$p"
  # shellcheck disable=SC2046
  gt=($(truth "$kind"))
  cells=()
  for candidates in "$default" "$default | Image_descriptor=DenseVLAD Image_sequences=10,20,40"; do
    "$exe" "$root/config/presets/auto.txt" "${common[@]}" "${gt[@]}" --set Images_path="$ref" \
      --set Images_path_2="$query" --set "Auto_candidates=$candidates" > "$work/auto.json"
    IFS='|' read -r r1 auc _ acc prec rel chosen _ <<< "$(figures "$work/auto.json")"
    cells+=("$r1 / $auc / $acc ($prec) / $chosen${rel:+, reliable: $rel}")
  done
  echo "| $name | ${cells[0]} | ${cells[1]} |"
done
