#!/usr/bin/env bash
# Robustness table of docs/benchmarks.md (sensor noise and light): a descriptor on KITTI 00
# (frames 0-1699) and Nordland (winter vs summer, L=10) with the protocols of
# bench/evaluation_table.sh, clean and with the side-window paper's disturbances (Gaussian
# variance 0.003, salt-and-pepper 10 %, overexposure: exposure doubled), each noisy run also
# with side-window fusion. Prints Markdown rows, and for KITTI the share of the AUC lost to the
# noise that fusion recovers: (AUC fused - AUC noisy) / (AUC clean - AUC noisy).
# Usage: bench/robustness.sh [descriptor ...]   (default: LDB)
#   RADII="1,2,3"        side-window radii of the main rows
#   ALT_RADII="1 1,1 2,2 1,2,3,4"  radii also tried on KITTI (space-separated; "" = none)
#   NORDLAND=0           skip Nordland
#   MAIN=0               skip the main rows (and the bar)
#   SUPPLEMENT=1         also: KITTI with the Gaussian noise of seeds 2 and 3 (run-to-run spread
#                        of the noise alone), and KITTI at Patch_size 256 (less averaging of the
#                        noise by the resize to the patch), clean / noisy / fused
source "$(dirname "$0")/common.sh"
data="$datasets"
prepare "$data" "$exe"
descriptors=("$@")
[ ${#descriptors[@]} -gt 0 ] || descriptors=(LDB)
radii="${RADII:-1,2,3}"
alt_radii="${ALT_RADII-1 1,1 2,2 1,2,3,4}"
nordland="${NORDLAND:-1}"
main="${MAIN:-1}"
supplement="${SUPPLEMENT:-0}"

declare -A auc
run() {  # run DATA TAG DISTURBANCE FUSION SETTING... : one row; AUC kept as auc[TAG]
  local data_name=$1 tag=$2 disturbance=$3 fusion=$4; shift 4
  local start end
  start=$(date +%s.%N)
  "$exe" --quiet --set Evaluation_name="$out/e" --set Noise_seed=1 "$@" > "$out/report"
  end=$(date +%s.%N)
  auc[$tag]=$(figure auc "$out/e.json")
  printf '| %s | %s | %s | %s | %.3f | %.4f | %.0f s |\n' "$data_name" "$d" "$disturbance" "$fusion" \
    "$(figure recall_at_1 "$out/e.json")" "${auc[$tag]}" \
    "$(awk -v a="$start" -v b="$end" 'BEGIN{print b-a}')"
}

noises=("none|" "Gaussian 0.003|--set Noise_gaussian=0.003"
        "salt-and-pepper 10 %|--set Noise_salt_pepper=0.1"
        "overexposure x2|--set Noise_overexposure=1")

# noise_rows DATA PREFIX ALTERNATIVES SETTING...: for each disturbance k, the row without fusion
# (AUC kept as auc[PREFIXk]); for the noisy ones also the row fused with $radii (auc[PREFIXkf])
# and one fused with each radii of ALTERNATIVES (space-separated).
noise_rows() {
  local data_name=$1 prefix=$2 alternatives=$3; shift 3
  local k name set a
  for k in "${!noises[@]}"; do
    name="${noises[$k]%%|*}"; read -r -a set <<< "${noises[$k]#*|}"
    run "$data_name" "$prefix$k" "$name" "off" "$@" "${set[@]}"
    [ "$k" -eq 0 ] && continue
    run "$data_name" "$prefix${k}f" "$name" "$radii" "$@" "${set[@]}" \
      --set Side_window=1 --set Side_window_radii="$radii"
    for a in $alternatives; do
      run "$data_name" "$prefix${k}a$a" "$name" "$a (alternative)" "$@" "${set[@]}" \
        --set Side_window=1 --set Side_window_radii="$a"
    done
  done
}

echo "| data | descriptor | disturbance | side-window radii | R@1 | AUC | wall time |"
echo "|---|---|---|---|---|---|---|"
for d in "${descriptors[@]}"; do
  kitti=(--set Images_path="$data/kitti00_first1700/image_0" --set Image_descriptor="$d"
         --set Image_sequences=1 --set Ground_truth_type=kitti
         --set Ground_truth="$data/kitti00_first1700/poses/00_first1700.txt"
         --set Ground_truth_axes=xz --set Ground_truth_heading=45 --set Exclusion=100
         --set Tolerance=3)
  nord=(--set Images_path="$data/nordland_trimmed/summer"
        --set Images_path_2="$data/nordland_trimmed/winter" --set Image_descriptor="$d"
        --set Image_sequences=10 --set Ground_truth_type=aligned --set Tolerance=2)
  if [ "$supplement" = 1 ]; then
    for seed in 2 3; do
      run "KITTI 00 0-1699, Noise_seed $seed" "s$seed" "Gaussian 0.003" "off" "${kitti[@]}" \
        --set Noise_gaussian=0.003 --set Noise_seed=$seed
    done
    for k in 0 1 2; do
      name="${noises[$k]%%|*}"; read -r -a set <<< "${noises[$k]#*|}"
      run "KITTI 00 0-1699, Patch_size 256" "p$k" "$name" "off" "${kitti[@]}" "${set[@]}" \
        --set Patch_size=256
      [ "$k" -eq 0 ] && continue
      run "KITTI 00 0-1699, Patch_size 256" "p${k}f" "$name" "$radii" "${kitti[@]}" "${set[@]}" \
        --set Patch_size=256 --set Side_window=1 --set Side_window_radii="$radii"
    done
  fi
  [ "$main" = 1 ] || continue
  noise_rows "KITTI 00 0-1699" k "$alt_radii" "${kitti[@]}"
  if [ "$nordland" = 1 ]; then
    noise_rows "Nordland winter vs summer, L=10" n "" "${nord[@]}"
  fi
  # The bar: on KITTI, fusion recovers at least half of the AUC the noise removed.
  echo
  echo "$d, KITTI 00, AUC recovered by side-window fusion (radii $radii), bar 0.5:"
  for k in 1 2 3; do
    name="${noises[$k]%%|*}"
    awk -v c="${auc[k0]}" -v n="${auc[k$k]}" -v f="${auc[k${k}f]}" -v name="$name" 'BEGIN{
      lost = c - n; rec = lost > 0 ? (f - n) / lost : 0;
      printf "- %s: clean %.4f, noisy %.4f, fused %.4f: lost %.4f, recovered %.0f %% (%s)\n",
             name, c, n, f, lost, 100 * rec, lost <= 0 ? "no loss" : (rec >= 0.5 ? "bar met" : "bar NOT met") }'
  done
done
