#!/usr/bin/env bash
# End-to-end scale benchmark: N query frames against N reference frames (real
# Nordland frames repeated and perturbed, bench/make_scale_data.cc), LDB 256 bits, L = 10,
# Best_matches 10, for N in the arguments (default 1000 10000 50000 100000). Dense mode where
# the (2N)^2 matrix fits in 16 GiB, bounded mode always. Prints wall time, pairs per second and
# peak memory (GNU time) per run. Frames are cached in $OPENABLE_SCALE_DATA (default
# build/scale_data; about 3 KB per frame).
# Usage: bench/scale.sh [N ...]
source "$(dirname "$0")/common.sh"
sizes=("$@"); [ ${#sizes[@]} -gt 0 ] || sizes=(1000 10000 50000 100000)
prepare "$datasets/nordland_trimmed" "$exe" "$root/build/bench/make_scale_data"
printf "%-8s %-8s %10s %14s %12s\n" N mode "wall (s)" "pairs/s" "peak (MiB)"
for n in "${sizes[@]}"; do
  scale_data "$n"
  for mode in 1 2; do
    total=$((2 * n))
    if [ "$mode" = 1 ] && [ $((total * total * 4 / 1024 / 1024 / 1024)) -ge 16 ]; then continue; fi
    /usr/bin/time -f "%e %M" -o "$out/time" "$exe" --quiet \
      --set Images_path="$dir/summer" --set Images_path_2="$dir/winter" \
      --set Image_descriptor=LDB --set Patch_size=64 --set Image_sequences=10 \
      --set Matrix_mode=$mode --set Best_matches=10 --set Matches_name="$out/m.npy" \
      --set Memory_limit=20 > "$out/report"
    read -r wall kib < "$out/time"
    # Dense computes the whole (2N)^2 matrix; bounded the N x N query-reference block.
    if [ "$mode" = 1 ]; then pairs=$((total * total)); name=dense; else pairs=$((n * n)); name=bounded; fi
    awk -v n="$n" -v m="$name" -v w="$wall" -v p="$pairs" -v k="$kib" \
      'BEGIN { printf "%-8s %-8s %10.2f %14.3g %12.0f\n", n, m, w, p / w, k / 1024 }'
  done
done
