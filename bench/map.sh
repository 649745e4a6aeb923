#!/usr/bin/env bash
# Maps against the batch run (docs/benchmarks.md, "Maps: settings chosen from their sessions"
# and "Maps: query time").
#
#   bench/map.sh accuracy   each pair of traversals of ../shared/datasets as two sessions of
#                           one map made with the auto preset, tuned (openable_map tune), the
#                           second queried against the first: the map's choice, R@1, AUC,
#                           accepted matches and their precision, beside the choice and
#                           figures of Test_OpenABLE's auto mode on the same frames; unrelated
#                           stretches must be judged unreliable. One Markdown row a pair.
#   bench/map.sh speed [N]  a HOG map of Nordland summer queried with winter at L = 40, against
#                           Test_OpenABLE's run of the same matrix (HOG, L = 40, scale, no
#                           files written); N pairs (default 5) run alternately, the medians and
#                           the ratio printed, with the CPU's model.
set -euo pipefail
source "$(dirname "$0")/common.sh"
map_exe="$root/build/examples/openable_map"
need_built "$exe" "$map_exe"
nl="$datasets/nordland_trimmed"
gp="$datasets/gardens_point"
auto="$root/config/presets/auto.txt"
temp_out

# part NAME FOLDER FIRST COUNT: a folder of links to files FIRST.. (1-based, natural order).
part() {
  local dir="$out/parts/$1"
  mkdir -p "$dir"
  ls "$2" | sort -V | sed -n "$3,$(($3 + $4 - 1))p" | while read -r f; do ln -s "$2/$f" "$dir/$f"; done
}

# pair LABEL REFERENCE QUERY [aligned]: one row.
pair() {
  local label=$1 reference=$2 query=$3 truth=${4:-}
  local map="$out/$RANDOM.map" prefix="$out/q$RANDOM"
  "$map_exe" add "$map" --images "$reference" --session reference --config "$auto" -q
  "$map_exe" add "$map" --images "$query" --session query -q
  "$map_exe" tune "$map" --json > "$out/tune.json" 2> /dev/null
  local gt=()
  [ -n "$truth" ] && gt=(--set Ground_truth_type=aligned --set Tolerance=2)
  "$map_exe" query "$map" --images "$query" --session reference --output "$prefix" -q "${gt[@]}"
  "$exe" "$auto" --json --set "Images_path=$reference" --set "Images_path_2=$query" \
    --set Npy_name= --set Png_name= --set Evaluation_name= "${gt[@]}" > "$out/batch.json" 2> /dev/null
  python3 - "$label" "$out/tune.json" "$prefix" "$out/batch.json" <<'EOF'
import json, sys
label, tune, prefix, batch = sys.argv[1:]
t = json.load(open(tune))["tuning"]
b = json.load(open(batch))
queries = json.load(open(prefix + ".json"))["queries"]
accepted = sum(q["accepted"] for q in queries)
try:
    p = json.load(open(prefix + "_eval.json"))["runs"][0]["per_query"]
    figures = "%.3f | %.3f | %d | %.3f" % (p["recall_at_1"], p["auc"], accepted,
                                          p["accepted"]["precision"])
except FileNotFoundError:
    figures = "- | - | %d | -" % accepted
bp = b.get("evaluation", {}).get("runs", [{}])[0].get("per_query") if b.get("evaluation") else None
batch_figures = "%.3f / %.3f" % (bp["recall_at_1"], bp["auc"]) if bp else "-"
print("| %s | %s | %s | %s | %.3f | %s | %s | %s |" % (
    label, t["chosen"], t["verdict"], figures, t["consistency"], b["auto"]["chosen"],
    "reliable" if b["auto"]["reliable"] else "unreliable", batch_figures))
EOF
}

accuracy() {
  echo "| pair | map's choice | verdict | R@1 | AUC | accepted | precision | consistency | auto mode's choice | its verdict | its R@1 / AUC |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
  need_data "$nl"
  pair "Nordland winter vs summer" "$nl/summer" "$nl/winter" aligned
  pair "Nordland summer vs winter" "$nl/winter" "$nl/summer" aligned
  pair "bundled sample, winter vs summer" "$root/examples/data/nordland_sample/summer" \
    "$root/examples/data/nordland_sample/winter" aligned
  if [ -d "$gp" ]; then
    pair "Gardens Point day_right vs day_left" "$gp/day_left" "$gp/day_right" aligned
    pair "Gardens Point day_left vs day_right" "$gp/day_right" "$gp/day_left" aligned
  fi
  # Synthetic night-like queries (build/bench/make_night, as bench/auto.sh makes them: the
  # datasets have no night traversal).
  local night="$root/build/bench/make_night"
  if [ -x "$night" ] && [ -d "$gp" ]; then
    "$night" "$gp/day_right" --strong --seed 2 "$out/gp_night_strong" > /dev/null
    pair "*Gardens Point strong night-like day_right vs day_left" "$gp/day_left" \
      "$out/gp_night_strong" aligned
    "$night" "$nl/winter" --seed 4 "$out/nord_winter_night" > /dev/null
    pair "*Nordland night-like winter vs summer" "$nl/summer" "$out/nord_winter_night" aligned
  fi
  part summer_a "$nl/summer" 1 600
  part winter_b "$nl/winter" 1101 600
  pair "Unrelated: Nordland winter 1100-1699 vs summer 0-599" "$out/parts/summer_a" "$out/parts/winter_b"
}

speed() {
  local pairs=${1:-5}
  need_data "$nl"
  lscpu | grep -E "^Model name|^CPU\(s\)" | sed 's/  */ /g'
  "$map_exe" add "$out/hog.map" --images "$nl/summer" --session summer \
    --set Image_descriptor=HOG -q
  local map_cmd=("$map_exe" query "$out/hog.map" --images "$nl/winter" --session summer
                 --set Image_sequences=40 --set Match_score=ratio --json)
  local run_cmd=("$exe" "$root/config/Config.txt" --quiet --set "Images_path=$nl/summer"
                 --set "Images_path_2=$nl/winter" --set Image_descriptor=HOG
                 --set Image_sequences=40 --set Sequence_partial=scale --set Txt_name=
                 --set Npy_name= --set Png_name= --set Match_score=ratio)
  "${map_cmd[@]}" > /dev/null 2>&1; "${run_cmd[@]}" > /dev/null 2>&1  # warm the page cache
  local a=() b=()
  for ((i = 0; i < pairs; ++i)); do
    local t0 t1 t2
    t0=$(date +%s.%N); "${map_cmd[@]}" > /dev/null 2>&1
    t1=$(date +%s.%N); "${run_cmd[@]}" > /dev/null 2>&1
    t2=$(date +%s.%N)
    a+=("$(echo "$t1 - $t0" | bc)"); b+=("$(echo "$t2 - $t1" | bc)")
  done
  python3 - "${a[*]}" "${b[*]}" <<'EOF'
import statistics, sys
a = [float(x) for x in sys.argv[1].split()]
b = [float(x) for x in sys.argv[2].split()]
ratios = [x / y for x, y in zip(a, b)]
print("map query (HOG, L = 40, 1788 queries against 1788 frames): median %.2f s (%.2f-%.2f)"
      % (statistics.median(a), min(a), max(a)))
print("Test_OpenABLE, the same matrix (3576 frames described): median %.2f s (%.2f-%.2f)"
      % (statistics.median(b), min(b), max(b)))
print("ratio map / Test_OpenABLE pair by pair: median %.2f (%.2f-%.2f)"
      % (statistics.median(ratios), min(ratios), max(ratios)))
EOF
}

case "${1:-}" in
  accuracy) accuracy ;;
  speed) speed "${2:-5}" ;;
  *) fail "usage: bench/map.sh accuracy | speed [pairs]" ;;
esac
