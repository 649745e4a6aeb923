#!/usr/bin/env bash
# The figures behind config/presets/ and the "Presets and the match score" section of
# docs/benchmarks.md, on ../shared/datasets, with the project's own evaluation:
#   1. the sweeps the presets were chosen from (openable_sweep): 240 combinations on Nordland
#      (winter vs summer, +-2) and on Gardens Point (day_right vs day_left, +-2), 280 on KITTI 00
#      frames 0-1699 (loop closure, 5 m x-z, heading < 45, +-3, exclusion 100), 32 on the
#      RTAB-Map sample (pairs, +-1, exclusion 10); the settings ranked by their worse AUC over
#      the two across-conditions datasets;
#   2. each preset run as a user runs it (Test_OpenABLE config/presets/...), beside the original
#      default (LDB L = 1), the best single settings before the match score and SeqSLAM (SAD
#      with contrast enhancement, Sequence_partial skip as OpenSeqSLAM, L = 10 and 30);
#   3. the sweep's wall time for 4 descriptors x 4 lengths x 2 scores on Nordland against the
#      same 32 runs of Test_OpenABLE.
# Usage: bench/presets.sh [sweeps|table|timing ...]   (default: all three; about 4 minutes on
# 2 cores). Files go to a temporary folder, or to $OPENABLE_BENCH_OUT when set.
source "$(dirname "$0")/common.sh"
data="$datasets"
sweep="$root/build/examples/openable_sweep"
need_data "$data"
need_built "$exe" "$sweep"
if [ -n "${OPENABLE_BENCH_OUT:-}" ]; then
  out="$OPENABLE_BENCH_OUT"
  mkdir -p "$out"
else
  temp_out
fi
parts=("$@")
[ ${#parts[@]} -gt 0 ] || parts=(sweeps table timing)

nordland=(--set Images_path="$data/nordland_trimmed/summer"
          --set Images_path_2="$data/nordland_trimmed/winter"
          --set Ground_truth_type=aligned --set Tolerance=2)
gardens=(--set Images_path="$data/gardens_point/day_left"
         --set Images_path_2="$data/gardens_point/day_right"
         --set Ground_truth_type=aligned --set Tolerance=2)
kitti=(--set Images_path="$data/kitti00_first1700/image_0" --set Ground_truth_type=kitti
       --set Ground_truth="$data/kitti00_first1700/poses/00_first1700.txt"
       --set Ground_truth_axes=xz --set Ground_truth_heading=45 --set Exclusion=100
       --set Tolerance=3)
rtabmap=(--set Images_path="$data/rtabmap_samples/images" --set Ground_truth_type=pairs
         --set Ground_truth="$data/rtabmap_samples/ground_truth_pairs.txt"
         --set Ground_truth_base=1 --set Exclusion=10 --set Tolerance=1)
no_files=(--set Txt_name= --set Npy_name= --set Png_name= --set Evaluation_name=)

for part in "${parts[@]}"; do
  case "$part" in
  sweeps)
    across=(--vary Image_descriptor=LDB,HOG,SIFT,SAD,HOG+LDB,HOG+SIFT
            --vary Image_sequences=1,10,20,30,40 --vary Match_score=distance,ratio
            --vary Sequence_partial=scale,skip --vary Contrast_enhancement=0,1
            --set Fusion_weights=1,1)
    "$sweep" --quiet "${no_files[@]}" "${nordland[@]}" "${across[@]}" --output "$out/nordland" \
      | sed -n 1,12p
    "$sweep" --quiet "${no_files[@]}" "${gardens[@]}" "${across[@]}" --output "$out/gardens" \
      | sed -n 1,12p
    "$sweep" --quiet "${no_files[@]}" "${kitti[@]}" --set Fusion_weights=1,1 \
      --vary Image_descriptor=LDB,HOG,SIFT,SAD,ORB,HOG+LDB,SIFT+LDB \
      --vary Image_sequences=1,3,5,10,20 --vary Match_score=distance,ratio \
      --vary Sequence_partial=scale,skip --vary Contrast_enhancement=0,1 \
      --output "$out/kitti" | sed -n 1,12p
    "$sweep" --quiet "${no_files[@]}" "${rtabmap[@]}" --vary Image_descriptor=LDB,SIFT,HOG,SAD \
      --vary Image_sequences=1,3,5,10 --vary Match_score=distance,ratio --output "$out/rtabmap" \
      | sed -n 1,12p
    echo "Across conditions: the settings ranked by their worse AUC over Nordland and Gardens Point"
    /usr/bin/python3 - "$out/nordland.csv" "$out/gardens.csv" <<'PY'
import csv, sys
def load(path):
    keys = ("Image_descriptor", "Image_sequences", "Match_score", "Sequence_partial",
            "Contrast_enhancement")
    return {tuple(r[k] for k in keys): r for r in csv.DictReader(open(path))}
n, g = load(sys.argv[1]), load(sys.argv[2])
both = sorted(n.keys() & g.keys(),
              key=lambda k: -min(float(n[k]["auc"]), float(g[k]["auc"])))
print("| descriptor | L | score | partial | contrast | Nordland R@1 / AUC / R@100P "
      "| Gardens Point R@1 / AUC / R@100P |")
print("|---|---|---|---|---|---|---|")
def f(r):
    return "%.3f / %.3f / %.3f" % (float(r["recall_at_1"]), float(r["auc"]),
                                    float(r["recall_at_100p"]))
for k in both[:10]:
    print("| %s | %s | %s | %s | %s | %s | %s |" % (k + (f(n[k]), f(g[k]))))
for name, a, b in (("Nordland", n, g), ("Gardens Point", g, n)):
    best = max(a, key=lambda k: float(a[k]["auc"]))
    print("best by AUC on %s alone: %s -> there %s, on the other %s"
          % (name, " ".join(best), f(a[best]), f(b[best])))
PY
    ;;
  table)
    echo "| data | setting | R@1 | AUC | R@100P | max F1 | accepted (precision) | wall time |"
    echo "|---|---|---|---|---|---|---|---|"
    row() {  # row DATA NAME CONFIG SETTING...
      local data_name=$1 name=$2 config=$3; shift 3
      local start end accepted
      start=$(date +%s.%N)
      "$exe" "$config" --quiet "${no_files[@]}" --set Evaluation_name="$out/e" "$@" > "$out/report"
      end=$(date +%s.%N)
      accepted="-"
      if grep -q '"accepted"' "$out/e.json"; then
        accepted="$(grep -o '"matches": [0-9]*' "$out/e.json" | head -1 | awk '{print $2}') ($(grep -o '"accepted": {[^}]*' "$out/e.json" | grep -o '"precision": [-0-9.e]*' | awk '{printf "%.3f", $2}'))"
      fi
      printf '| %s | %s | %.3f | %.3f | %.3f | %.3f | %s | %.1f s |\n' "$data_name" "$name" \
        "$(figure recall_at_1 "$out/e.json")" "$(figure auc "$out/e.json")" \
        "$(figure recall_at_100p "$out/e.json")" "$(figure max_f1 "$out/e.json")" \
        "$accepted" "$(awk -v a="$start" -v b="$end" 'BEGIN{print b-a}')"
    }
    defaults="$root/config/Config.txt"
    across="$root/config/presets/across_conditions.txt"
    loop="$root/config/presets/loop_closure.txt"
    seqslam=(--set Image_descriptor=SAD --set Contrast_enhancement=1 --set Sequence_partial=skip
             --set Threshold=-1)
    plain=(--set Threshold=-1)
    for d in nordland gardens; do
      if [ $d = nordland ]; then name="Nordland"; set_=("${nordland[@]}"); else
        name="Gardens Point"; set_=("${gardens[@]}"); fi
      row "$name" "LDB L=1 (the original's default)" "$defaults" "${set_[@]}" "${plain[@]}" \
        --set Image_sequences=1
      row "$name" "HOG L=30, distance (best before the score)" "$defaults" "${set_[@]}" \
        "${plain[@]}" --set Image_descriptor=HOG --set Image_sequences=30
      row "$name" "SIFT L=10, distance" "$defaults" "${set_[@]}" "${plain[@]}" \
        --set Image_descriptor=SIFT --set Image_sequences=10
      row "$name" "SeqSLAM: SAD + contrast, L=10" "$defaults" "${set_[@]}" "${seqslam[@]}" \
        --set Image_sequences=10
      row "$name" "SeqSLAM: SAD + contrast, L=30" "$defaults" "${set_[@]}" "${seqslam[@]}" \
        --set Image_sequences=30
      row "$name" "**across_conditions preset**" "$across" "${set_[@]}"
    done
    for d in kitti rtabmap; do
      if [ $d = kitti ]; then name="KITTI 00 0-1699"; set_=("${kitti[@]}"); else
        name="RTAB-Map sample"; set_=("${rtabmap[@]}"); fi
      row "$name" "LDB L=1 (the original's default)" "$defaults" "${set_[@]}" "${plain[@]}" \
        --set Image_sequences=1 --set Images_path_2=
      row "$name" "SIFT L=1, distance (best before the score)" "$defaults" "${set_[@]}" \
        "${plain[@]}" --set Image_descriptor=SIFT --set Image_sequences=1 --set Images_path_2=
      row "$name" "SeqSLAM: SAD + contrast, L=10" "$defaults" "${set_[@]}" "${seqslam[@]}" \
        --set Image_sequences=10 --set Images_path_2=
      row "$name" "**loop_closure preset**" "$loop" "${set_[@]}"
      row "$name" "loop_closure preset, ratio, Match_threshold 0.6" "$loop" "${set_[@]}" \
        --set Match_score=ratio --set Match_threshold=0.6
    done
    ;;
  timing)
    echo "Nordland, 4 descriptors x 4 lengths x 2 scores (32 runs):"
    start=$(date +%s.%N)
    "$sweep" --quiet "${no_files[@]}" "${nordland[@]}" --vary Image_descriptor=LDB,HOG,SIFT,SAD \
      --vary Image_sequences=1,10,20,30 --vary Match_score=distance,ratio \
      --output "$out/timing" > /dev/null
    end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN{printf "  openable_sweep: %.1f s\n", b-a}'
    start=$(date +%s.%N)
    for d in LDB HOG SIFT SAD; do
      for l in 1 10 20 30; do
        for s in distance ratio; do
          "$exe" --quiet "${no_files[@]}" "${nordland[@]}" --set Image_descriptor=$d \
            --set Image_sequences=$l --set Match_score=$s > /dev/null
        done
      done
    done
    end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN{printf "  32 runs of Test_OpenABLE: %.1f s\n", b-a}'
    ;;
  *)
    echo "presets.sh: unknown part \"$part\"; expected sweeps, table or timing" >&2
    exit 2
    ;;
  esac
done
