#!/usr/bin/env bash
# The Nordland benchmark: Nordland trimmed, winter against summer (1788 + 1788 frames), LDB, global
# 64x64, L = 10 by default. Prints R@1 (share of winter frames whose best summer match lies within
# +-2 frames), wall time and peak memory of Test_OpenABLE (GNU time), for docs/benchmarks.md.
# Usage: bench/nordland_bar.sh [--set Key=Value ...]   (from anywhere; needs ../shared/datasets)
source "$(dirname "$0")/common.sh"
data="$datasets/nordland_trimmed"
prepare "$data" "$exe"
/usr/bin/time -f "wall %e s, peak RSS %M KiB" -o "$out/time" \
  "$exe" --quiet --set Images_path="$data/summer" --set Images_path_2="$data/winter" \
  --set Image_descriptor=LDB --set Description_type=0 --set Patch_size=64 \
  --set Image_sequences=10 --set Npy_name="$out/m.npy" "$@" > "$out/report"
sed -n '1,4p' "$out/report"
cat "$out/time"
/usr/bin/python3 - "$out/m.npy" <<'PY'
import sys
import numpy as np
m = np.load(sys.argv[1])
n = m.shape[0] // 2
cross = m[n:, :n]  # winter rows against summer columns
best = cross.argmin(axis=1)
r1 = np.mean(np.abs(best - np.arange(n)) <= 2)
print(f"R@1 (+-2 frames), winter vs summer: {r1:.3f}  (original OpenABLE: 0.355 at L=10)")
PY
