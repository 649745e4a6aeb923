# Sourced by the benchmark scripts of bench/ (source "$(dirname "$0")/common.sh"): strict mode,
# where the tree, the datasets and the programs are, and the checks and helpers they share.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
datasets="$root/../shared/datasets"
exe="$root/build/examples/Test_OpenABLE"
script="$(basename "$0")"

# fail MESSAGE...: ends the script with "<script>: MESSAGE" on stderr.
fail() {
  echo "$script: $*" >&2
  exit 1
}

# need_data DIR: ends the script when DIR, a folder of ../shared/datasets, is absent.
need_data() {
  [ -d "$1" ] || fail "$1 not found (see ../shared/datasets/README.md)"
}

# need_built PROGRAM...: ends the script when a program of the build is missing.
need_built() {
  local program
  for program; do
    [ -x "$program" ] || fail "$program not built (run examples/setup.sh)"
  done
}

# temp_out: sets out to a fresh temporary folder, removed when the script exits.
temp_out() {
  out="$(mktemp -d)"
  trap 'rm -rf "$out"' EXIT
}

# prepare DIR PROGRAM...: need_data DIR, need_built PROGRAM..., then temp_out.
prepare() {
  need_data "$1"
  shift
  need_built "$@"
  temp_out
}

# figure KEY FILE: the first number after "KEY": in a JSON file.
figure() {
  grep -o "\"$1\": [-0-9.e]*" "$2" | head -1 | awk '{print $2}'
}

# scale_data N: sets dir to the folder of N summer and N winter frames (real Nordland frames
# repeated and perturbed by build/bench/make_scale_data), made on first use and cached in
# $OPENABLE_SCALE_DATA (default build/scale_data; about 3 KB per frame).
scale_data() {
  dir="${OPENABLE_SCALE_DATA:-$root/build/scale_data}/$1"
  if [ ! -f "$dir/.done" ]; then
    "$root/build/bench/make_scale_data" "$datasets/nordland_trimmed" "$dir" "$1" &&
      touch "$dir/.done"
  fi
}

# link_part DIR FOLDER FIRST COUNT: DIR holds links to the files FIRST.. FIRST + COUNT - 1
# (1-based, natural order of their names) of FOLDER, a part of a traversal (made once).
link_part() {
  local dir="$1"
  [ -d "$dir" ] && return
  mkdir -p "$dir"
  ls "$2" | sort -V | sed -n "$3,$(($3 + $4 - 1))p" | while read -r f; do ln -s "$2/$f" "$dir/$f"; done
}

# night_like FOLDER NAME SOURCE ARGS...: FOLDER/NAME made once by build/bench/make_night from
# SOURCE (synthetic night-like frames; ARGS as make_night takes them).
night_like() {
  [ -d "$1/$2" ] || "$root/build/bench/make_night" "$3" "${@:4}" "$1/$2" > /dev/null
}
