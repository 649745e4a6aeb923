#!/usr/bin/env bash
# DenseVLAD against HOG and SIFT where the viewpoint and the light change together: Gardens
# Point day_right against day_left (the other side of the path) and night-like variants of
# day_right (build/bench/make_night, as bench/auto.sh makes them) against day_left, at L = 1, 10
# and 40, with the auto preset's matching (ratio score <= 0.9, confirmed by one independent
# query) and Auto 0. Then the auto mode with and without DenseVLAD among its candidates on the
# shared pairs. Prints Markdown rows (docs/benchmarks.md, "A descriptor for viewpoint and light
# together"). Usage: bench/viewpoint_light.sh [work folder] (default: a temporary folder).
source "$(dirname "$0")/common.sh"
gp="$datasets/gardens_point"; nl="$datasets/nordland_trimmed"
need_data "$gp"
need_built "$exe" "$root/build/bench/make_night"
if [ $# -ge 1 ]; then work="$1"; mkdir -p "$work"; else temp_out; work="$out"; fi
night="$work/night"; mkdir -p "$night"
make() { [ -d "$night/$1" ] || "$root/build/bench/make_night" "${@:2}" "$night/$1" > /dev/null; }
make gp_right_night "$gp/day_right" --seed 1
make gp_right_night_strong "$gp/day_right" --strong --seed 2
make gp_right_night_extreme "$gp/day_right" --strong --seed 6 --zoom 0.15 --shift 0.08 --rotation 5 --noise 1.5
part() {  # part NAME FOLDER FIRST COUNT: files FIRST.. (1-based) of FOLDER in natural order
  local dir="$work/parts/$1"; [ -d "$dir" ] && return; mkdir -p "$dir"
  ls "$2" | sort -V | sed -n "$3,$(($3 + $4 - 1))p" | while read -r f; do ln -s "$2/$f" "$dir/$f"; done
}
part nord_s0 "$nl/summer" 1 300; part nord_w0 "$nl/winter" 1 300
part nord_w600 "$nl/winter" 601 300; part nord_s600 "$nl/summer" 601 300
part nord_summer_a "$nl/summer" 1 300; part nord_winter_b "$nl/winter" 1101 300
part nord_winter_c "$nl/winter" 1101 200
part rtab_lap1 "$datasets/rtabmap_samples/images" 1 40; part rtab_lap2 "$datasets/rtabmap_samples/images" 41 44
awk '!/^#/ && $1 >= 41 && $2 <= 40 {print $1 - 41 "," $2 - 1}' \
  "$datasets/rtabmap_samples/ground_truth_pairs.txt" > "$work/rtab_pairs.csv"

# figures JSON: "R@1|AUC|R@100P|accepted|precision|reliable|chosen" of a run's --json
figures() {
  python3 - "$1" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
e, a = j["evaluation"], j.get("auto")
if e:
    q = e["runs"][0]["per_query"]
    op = q.get("accepted", {})
    print("%.3f|%.3f|%.3f|%d|%.3f" % (q["recall_at_1"], q["auc"], q["recall_at_100p"],
                                      op.get("matches", 0), op.get("precision", 1)), end="")
else:
    print("-|-|-|%d|-" % (j["accepted"]["queries"] if j["accepted"] else 0), end="")
print("|%s|%s" % (("yes" if a["reliable"] else "**no**"), a["chosen"]) if a else "||")
PY
}
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
  "RTAB-Map sample, lap 2 vs lap 1|$work/parts/rtab_lap1|$work/parts/rtab_lap2|rtab"
  "Unrelated: Nordland winter 1100-1299 vs Gardens Point|$gp/day_left|$work/parts/nord_winter_c|none"
  "Unrelated: Nordland winter 1100-1399 vs summer 0-299|$work/parts/nord_summer_a|$work/parts/nord_winter_b|none"
)
for p in "${pairs[@]}"; do
  IFS='|' read -r name ref query kind <<< "$p"
  case "$kind" in
    aligned) gt=("${aligned[@]}") ;;
    rtab) gt=(--set Ground_truth_type=pairs --set Ground_truth="$work/rtab_pairs.csv" --set Ground_truth_base=0 --set Tolerance=1) ;;
    none) gt=() ;;
  esac
  cells=()
  for candidates in "$default" "$default | Image_descriptor=DenseVLAD Image_sequences=10,20,40"; do
    "$exe" "$root/config/presets/auto.txt" "${common[@]}" "${gt[@]}" --set Images_path="$ref" \
      --set Images_path_2="$query" --set "Auto_candidates=$candidates" > "$work/auto.json"
    IFS='|' read -r r1 auc _ acc prec rel chosen <<< "$(figures "$work/auto.json")"
    cells+=("$r1 / $auc / $acc ($prec) / $chosen${rel:+, reliable: $rel}")
  done
  echo "| $name | ${cells[0]} | ${cells[1]} |"
done
