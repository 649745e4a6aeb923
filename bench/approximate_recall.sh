#!/usr/bin/env bash
# Recall of Approximate_search (FLANN) against exact search on Nordland trimmed (winter queries
# against summer references, 1788 each): share of queries whose exact best match (dense run,
# same settings) is the approximate best (top-1) or among the approximate Best_matches (in-k),
# and the wall times. Usage: bench/approximate_recall.sh [descriptor] [L] [checks ...]
source "$(dirname "$0")/common.sh"
data="$datasets/nordland_trimmed"
desc="${1:-LDB}"; L="${2:-1}"; shift $(( $# > 2 ? 2 : $# )) || true
checks=("$@"); [ ${#checks[@]} -gt 0 ] || checks=(32 128 512)
prepare "$data" "$exe"
run() {  # name, extra settings...
  local name="$1"; shift
  /usr/bin/time -f "%e" -o "$out/$name.time" "$exe" --quiet --set Images_path="$data/summer" \
    --set Images_path_2="$data/winter" --set Image_descriptor="$desc" --set Patch_size=64 \
    --set Image_sequences="$L" --set Best_matches=10 --set Matches_name="$out/$name.npy" "$@" > /dev/null
}
run exact --set Matrix_mode=2
for c in "${checks[@]}"; do run "approx$c" --set Approximate_search=1 --set Approximate_engine=flann --set Approximate_checks="$c"; done
/usr/bin/python3 - "$out" "$desc" "$L" "${checks[@]}" <<'PY'
import sys, numpy as np
out, desc, L, checks = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
ex = np.load(f"{out}/exact.npy"); best = {int(q): int(r) for q, r in ex[ex['rank'] == 1][['query', 'reference']]}
t_ex = float(open(f"{out}/exact.time").read())
print(f"{desc} L={L}: exact (bounded) {t_ex:.2f} s")
for c in checks:
    a = np.load(f"{out}/approx{c}.npy"); t = float(open(f"{out}/approx{c}.time").read())
    top1 = {int(q): int(r) for q, r in a[a['rank'] == 1][['query', 'reference']]}
    ink = {}
    for q, r in a[['query', 'reference']]: ink.setdefault(int(q), set()).add(int(r))
    r1 = np.mean([top1.get(q) == r for q, r in best.items()])
    rk = np.mean([r in ink.get(q, ()) for q, r in best.items()])
    print(f"  checks {c:>4}: recall top-1 {r1:.3f}, exact best in approximate 10 {rk:.3f}, {t:.2f} s")
PY
