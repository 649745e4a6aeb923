#!/usr/bin/env bash
# Runs over several processes (docs/distributed.md): the bounded run of bench/scale.sh (N query
# frames against N references, real Nordland frames repeated and perturbed, LDB 256 bits,
# L = 10, Best_matches 10) as one process and as K processes under mpirun, each with T threads.
# Prints wall time, description and matching time of process 0, pairs per second and the
# parallel efficiency against one process with the same threads per process:
# efficiency = time(1 process) / (K x time(K processes)) with K x T cores in use.
# Usage: bench/distributed.sh [N] [K] [T]   (defaults 100000 2 1)
source "$(dirname "$0")/common.sh"
n="${1:-100000}"; k="${2:-2}"; t="${3:-1}"
command -v mpirun > /dev/null || fail "mpirun not found (Debian: openmpi-bin)"
prepare "$datasets/nordland_trimmed" "$exe" "$root/build/bench/make_scale_data"
scale_data "$n"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
args=(--set Images_path="$dir/summer" --set Images_path_2="$dir/winter"
      --set Image_descriptor=LDB --set Patch_size=64 --set Image_sequences=10
      --set Matrix_mode=2 --set Best_matches=10 --set Memory_limit=20 --set Threads="$t"
      --set Ground_truth_type= --set Evaluation_name=)
printf "%-10s %9s %10s %13s %12s %14s %11s\n" processes threads "wall (s)" "describe (s)" "match (s)" "pairs/s" efficiency
base=""
for procs in 1 "$k"; do
  if [ "$procs" = 1 ]; then
    launch=("$exe")
  else
    launch=(mpirun --quiet --oversubscribe --bind-to none -np "$procs" "$exe")
  fi
  start=$(date +%s.%N)
  "${launch[@]}" --quiet "${args[@]}" --set Matches_name="$out/m$procs.npy" > "$out/report$procs"
  wall=$(echo "$(date +%s.%N) - $start" | bc)
  describe=$(awk '/^  description/ {print $2}' "$out/report$procs")
  match=$(awk '/^  matching/ {print $2}' "$out/report$procs")
  [ -n "$base" ] || base=$wall
  awk -v p="$procs" -v t="$t" -v w="$wall" -v d="$describe" -v m="$match" -v n="$n" -v b="$base" \
    'BEGIN { printf "%-10s %9s %10.2f %13s %12s %14.3g %11.2f\n", p, t, w, d, m, n * n / w, b / (p * w) }'
done
cmp -s "$out/m1.npy" "$out/m$k.npy" && echo "matches: identical" || echo "matches: DIFFER"
