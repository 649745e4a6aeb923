#!/usr/bin/env bash
# The auto mode (config/presets/auto.txt) against the best candidate a sweep finds with ground
# truth, and against the across-conditions preset, on every pair of traversals of
# ../shared/datasets and on night-like variants made here (build/bench/make_night: synthetic,
# the datasets have no night traversal), plus pairs of unrelated traversals that must be judged
# unreliable. Prints one Markdown row per pair (docs/benchmarks.md, "Settings chosen from the
# data"). Usage: bench/auto.sh [work folder] (default: a temporary folder, removed at the end;
# give one to keep the night-like frames for bench/sequence_edges.py).
source "$(dirname "$0")/common.sh"
data="$root/../shared/datasets"
bin="$root/build/examples"
[ -d "$data" ] || { echo "auto.sh: $data not found" >&2; exit 1; }
if [ $# -ge 1 ]; then work="$1"; mkdir -p "$work"; else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
source "$(dirname "$0")/shared_pairs.sh"

aligned=(--set Ground_truth_type=aligned --set Tolerance=2)
pairs=(
  "Nordland winter vs summer|$nl/summer|$nl/winter|aligned"
  "Gardens Point day_right vs day_left|$gp/day_left|$gp/day_right|aligned"
  "Gardens Point day_left vs day_right|$gp/day_right|$gp/day_left|aligned"
  "Nordland 0-299, winter vs summer|$work/parts/nord_s0|$work/parts/nord_w0|aligned"
  "Nordland 600-899, summer vs winter|$work/parts/nord_w600|$work/parts/nord_s600|aligned"
  "Nordland 1200-1499, winter vs summer|$work/parts/nord_s1200|$work/parts/nord_w1200|aligned"
  "RTAB-Map sample, lap 2 vs lap 1|$work/parts/rtab_lap1|$work/parts/rtab_lap2|rtab"
  "KITTI 00 1500-1699 vs 40-260 (partial overlap)|$work/parts/kitti_ref|$work/parts/kitti_qry|kitti"
  "*GP night-like day_right vs day_right|$gp/day_right|$night/gp_right_night|aligned"
  "*GP night-like day_right vs day_left|$gp/day_left|$night/gp_right_night|aligned"
  "*GP strong night-like day_right vs day_left|$gp/day_left|$night/gp_right_night_strong|aligned"
  "*GP extreme night-like day_right vs day_left|$gp/day_left|$night/gp_right_night_extreme|aligned"
  "*Nordland night-like summer vs summer|$nl/summer|$night/nord_summer_night|aligned"
  "*Nordland night-like winter vs summer|$nl/summer|$night/nord_winter_night|aligned"
  "*Nordland strong night-like summer vs winter|$nl/winter|$night/nord_summer_night_strong|aligned"
  "*Nordland extreme night-like winter vs summer|$nl/summer|$night/nord_winter_night_extreme|aligned"
  "Sussex panoramas, re-run vs training (another speed)|$sx/training|$work/sussex_rerun|sussex"
  "Unrelated: Nordland winter 1100-1699 vs summer 0-599|$work/parts/nord_summer_a|$work/parts/nord_winter_b|none"
  "Unrelated: Nordland winter 1100-1299 vs Gardens Point|$gp/day_left|$work/parts/nord_winter_c|none"
)
best_auc() {  # the best AUC over the candidates of Auto_candidates, by openable_sweep
  python3 - "$@" <<'PY'
import json, sys
print("%.3f" % max(r["per_query"]["auc"] for f in sys.argv[1:] for r in json.load(open(f))["runs"]))
PY
}
echo "| pair | auto R@1 | AUC | R@100P | accepted | precision | reliable | chosen | consistency | best AUC by sweep | across_conditions AUC | accepted (precision) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for p in "${pairs[@]}"; do
  IFS='|' read -r name ref qry kind <<< "$p"
  # shellcheck disable=SC2046
  gt=($(truth "$kind"))
  set -- --quiet --set Images_path="$ref" --set Images_path_2="$qry" --set Npy_name= --set Png_name= \
    --set Evaluation_name= "${gt[@]}"
  "$bin/Test_OpenABLE" "$root/config/presets/auto.txt" "$@" --json > "$work/auto.json"
  row="$(figures "$work/auto.json")"
  if [ "$kind" != none ]; then
    "$bin/openable_sweep" "$root/config/presets/auto.txt" "$@" --set Auto=0 \
      --vary Image_descriptor=HOG,SIFT,LDB,HOG+LDB --vary Image_sequences=10,20,40 \
      --set Fusion_weights=1,1 --output "$work/s1" > /dev/null 2>&1
    "$bin/openable_sweep" "$root/config/presets/auto.txt" "$@" --set Auto=0 \
      --set Image_descriptor=SAD --set Contrast_enhancement=1 --vary Image_sequences=10,20,40 \
      --output "$work/s2" > /dev/null 2>&1
    best="$(best_auc "$work/s1.json" "$work/s2.json")"
    "$bin/Test_OpenABLE" "$root/config/presets/across_conditions.txt" "$@" --json > "$work/ac.json"
    ac="$(figures "$work/ac.json" | awk -F'|' '{printf "%s|%s (%s)", $2, $4, $5}')"
  else
    best="-"; ac="-|-"
  fi
  IFS='|' read -r r1 auc r100 acc prec rel chosen cons <<< "$row"
  echo "| $name | $r1 | $auc | $r100 | $acc | $prec | $rel | $chosen | $cons | $best | $ac |"
done
