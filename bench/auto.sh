#!/usr/bin/env bash
# The auto mode (config/presets/auto.txt) against the best candidate a sweep finds with ground
# truth, and against the across-conditions preset, on every pair of traversals of
# ../shared/datasets and on night-like variants made here (build/bench/make_night: synthetic,
# the datasets have no night traversal), plus pairs of unrelated traversals that must be judged
# unreliable. Prints one Markdown row per pair (docs/benchmarks.md, "Settings chosen from the
# data"). Usage: bench/auto.sh [work folder] (default: a temporary folder, removed at the end;
# give one to keep the night-like frames for bench/sequence_edges.py).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
data="$root/../shared/datasets"
bin="$root/build/examples"
[ -d "$data" ] || { echo "auto.sh: $data not found" >&2; exit 1; }
if [ $# -ge 1 ]; then work="$1"; mkdir -p "$work"; else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
night="$work/night"; mkdir -p "$night"
nd="$root/build/bench/make_night"
gp="$data/gardens_point"; nl="$data/nordland_trimmed"
make() { [ -d "$night/$1" ] || "$nd" "${@:2}" "$night/$1" > /dev/null; }
make gp_right_night "$gp/day_right" --seed 1
make gp_right_night_strong "$gp/day_right" --strong --seed 2
make gp_right_night_extreme "$gp/day_right" --strong --seed 6 --zoom 0.15 --shift 0.08 --rotation 5 --noise 1.5
make nord_summer_night "$nl/summer" --seed 3
make nord_winter_night "$nl/winter" --seed 4
make nord_summer_night_strong "$nl/summer" --strong --from-left --seed 5
make nord_winter_night_extreme "$nl/winter" --strong --from-left --seed 7 --zoom 0.1 --shift 0.06 --rotation 4 --noise 1.3

# Folders of parts of a traversal (links), and the ground truth of the parts.
part() {  # part NAME FOLDER FIRST COUNT: files FIRST.. (1-based) of FOLDER in natural order
  local dir="$work/parts/$1"; [ -d "$dir" ] && return; mkdir -p "$dir"
  ls "$2" | sort -V | sed -n "$3,$(($3 + $4 - 1))p" | while read -r f; do ln -s "$2/$f" "$dir/$f"; done
}
part nord_s0 "$nl/summer" 1 300; part nord_w0 "$nl/winter" 1 300
part nord_w600 "$nl/winter" 601 300; part nord_s600 "$nl/summer" 601 300
part nord_s1200 "$nl/summer" 1201 300; part nord_w1200 "$nl/winter" 1201 300
part nord_summer_a "$nl/summer" 1 600; part nord_winter_b "$nl/winter" 1101 600
part nord_winter_c "$nl/winter" 1101 200
part rtab_lap1 "$data/rtabmap_samples/images" 1 40; part rtab_lap2 "$data/rtabmap_samples/images" 41 44
part kitti_ref "$data/kitti00_first1700/image_0" 41 221; part kitti_qry "$data/kitti00_first1700/image_0" 1501 200
# RTAB-Map laps: images 41-84 revisit 1-40 (1-based ids in the pairs file).
awk '!/^#/ && $1 >= 41 && $2 <= 40 {print $1 - 41 "," $2 - 1}' \
  "$data/rtabmap_samples/ground_truth_pairs.txt" > "$work/rtab_pairs.csv"
sed -n '41,261p' "$data/kitti00_first1700/poses/00_first1700.txt" > "$work/kitti_ref_poses.txt"
# Sussex panoramas: the re-run's 96 tracked frames against the training route (true places within
# 30 cm of the tracked positions), as bench/sussex_panoramas.sh.
sx="$data/sussex_panoramas"
[ -d "$work/sussex_rerun" ] || "$root/build/bench/shift_panoramas" "$sx/test_infomax_binary" "$work/sussex_rerun" 0 96 > /dev/null
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$sx/gt_positions_training.txt" > "$work/sussex_train.csv"
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$sx/gt_positions_test_infomax_binary.txt" | head -96 > "$work/sussex_rerun.csv"
sed -n '1501,1700p' "$data/kitti00_first1700/poses/00_first1700.txt" > "$work/kitti_qry_poses.txt"

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
truth() {  # the ground-truth keys of a pair
  case "$1" in
    aligned) echo "--set Ground_truth_type=aligned --set Tolerance=2" ;;
    rtab) echo "--set Ground_truth_type=pairs --set Ground_truth=$work/rtab_pairs.csv --set Ground_truth_base=0 --set Tolerance=1" ;;
    kitti) echo "--set Ground_truth_type=kitti --set Ground_truth=$work/kitti_ref_poses.txt --set Ground_truth_2=$work/kitti_qry_poses.txt --set Ground_truth_axes=xz --set Ground_truth_radius=5 --set Ground_truth_heading=45 --set Tolerance=3" ;;
    sussex) echo "--set Ground_truth_type=positions --set Ground_truth=$work/sussex_train.csv --set Ground_truth_2=$work/sussex_rerun.csv --set Ground_truth_radius=30 --set Tolerance=0 --set Camera_type=2 --set Panoramas=4 --set Panorama_matching=0" ;;
    none) echo "" ;;
  esac
}
figures() {  # figures JSON: "R@1 AUC R@100P accepted precision reliable chosen consistency"
  python3 - "$1" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
e = j["evaluation"]
a = j.get("auto")
acc = j["accepted"]
if e:
    q = e["runs"][0]["per_query"]
    op = q.get("accepted", {})
    print("%.3f|%.3f|%.3f|%d|%.3f" % (q["recall_at_1"], q["auc"], q["recall_at_100p"],
                                      op.get("matches", 0), op.get("precision", 1)), end="")
else:
    print("-|-|-|%d|-" % (acc["queries"] if acc else 0), end="")
if a:
    c = [x for x in a["candidates"] if x["rank"] == 1][0]
    print("|%s|%s|%.3f" % ("yes" if a["reliable"] else "**no**", a["chosen"], c["consistency"]))
else:
    print()
PY
}
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
