#!/usr/bin/env bash
# End-to-end speed and memory of the original OpenABLE (Arroyo, 2016) against this
# Test_OpenABLE, on the same input, with the same configuration file and the same outputs.
#
# Usage: bench/vs_original.sh ORIGINAL_BINARY      (from anywhere; needs ../shared/datasets)
#        bench/vs_original.sh --help
#
# What it does
#   1. Lays the Nordland trimmed frames out the way the original reads them: one folder of
#      symbolic links 000000.png ... 003575.png (summer 0-1787, then winter 1788-3575, i.e.
#      both traversals as one sequence of 3,576 frames), and a second folder of 7,152 links
#      (the same 3,576 frames twice) for the memory figure.
#   2. Writes one old-style Config.txt per run (%YAML:1.0 and only the original's keys:
#      Frame_mode 0, Images_path with a trailing slash, Images_format png, Initial_image 0,
#      Final_image N, Camera_type 0, Description_type 0, Patch_size 64, Image_descriptor LDB,
#      Image_sequences L, Threshold -1, Txt_name similarity.txt, Png_name similarity.png,
#      Matrix_color 7, Show_images 0, and the unused keys with neutral values) and runs both
#      programs the same way, as the original must be run: `cd RUN_DIR && BINARY Config.txt`,
#      the file's path as the only argument. Both write the text matrix and the colour PNG of
#      the matrix into RUN_DIR; this program reads the old file unchanged (no .npy, since the
#      old file has no Npy_name; its default Threads, all cores, since it has no Threads key).
#   3. For each L (Image_sequences) of 1, 10, 30: 5 pairs of runs, each pair the original then
#      this program, every run timed by /usr/bin/time -f "%e %M" (wall time of the whole
#      process and peak RSS). After each run the outputs are checked (the text matrix has N
#      rows, the PNG is N x N, no error message in the program's output: the original exits
#      with status 0 even when it cannot read its input) and deleted.
#   4. One run of each at 7,152 frames, L = 10, for peak memory.
#   5. Prints a Markdown table for docs/benchmarks.md on stdout (progress on stderr): per L,
#      the median, min and max of the pair-by-pair ratios of wall time (original / ours), the
#      median wall times, and the largest peak RSS of each program's runs; then the 7,152-frame
#      row. The first lines name the machine (CPU model, cores, memory) and the date.
#
# Environment (all optional):
#   VS_ORIGINAL_RUNS=5          pairs of runs per L
#   VS_ORIGINAL_LENGTHS="1 10 30"   the values of Image_sequences
#   VS_ORIGINAL_MEMORY=1        0 skips the 7,152-frame run
#   VS_ORIGINAL_OURS=...        this project's Test_OpenABLE (default build/examples/Test_OpenABLE)
#   VS_ORIGINAL_DATA=...        Nordland trimmed folder with summer/ and winter/
#                               (default ../shared/datasets/nordland_trimmed)
#   TMPDIR                      where the temporary folder goes (removed on exit; the text
#                               matrix of a 7,152-frame run takes about 450 MB)
# A quick check of the script itself (well under a minute):
#   VS_ORIGINAL_RUNS=1 VS_ORIGINAL_LENGTHS="1" bench/vs_original.sh build/examples/Test_OpenABLE
# With the original, the full run takes several minutes (its L = 30 runs take tens of seconds
# each, its matching cost grows with N^2 x L).
#
# Exit status: 0 done; 1 bad argument, missing or non-executable binary, missing data, or a
# run that failed (one line on stderr saying what and what was expected).
#
# Building the original (public source: https://github.com/roberto-arroyo/OpenABLE; last
# commit seen: ec0070e, 2016). It is a small CMake project: one executable, Test_OpenABLE,
# from the toolbox class, the LDB library and the D-LDB stereo code, linked against whatever
# OpenCV find_package(OpenCV) finds. It was written for OpenCV 3 with the opencv_contrib
# module xfeatures2d (BRIEF, FREAK and SURF come from there; SIFT too in OpenCV 3).
#
#   Unchanged source, OpenCV 3.x:
#     1. Build OpenCV 3.4 together with opencv_contrib 3.4 from source
#        (-DOPENCV_EXTRA_MODULES_PATH=<opencv_contrib>/modules; SURF additionally needs
#        -DOPENCV_ENABLE_NONFREE=ON from 3.4.2 on) and install it to a prefix of your choice.
#     2. git clone https://github.com/roberto-arroyo/OpenABLE && cd OpenABLE
#     3. mkdir build && cd build
#        cmake -DCMAKE_BUILD_TYPE=Release -DOpenCV_DIR=<prefix>/share/OpenCV ..
#        make                       -> build/Test_OpenABLE
#     The project sets its own flags (-O3 -ffast-math, and -fbranch-probabilities, which does
#     nothing without profile data). CMake 3.x accepts its cmake_minimum_required(2.6)
#     with a deprecation warning; CMake 4 needs -DCMAKE_POLICY_VERSION_MINIMUM=3.5.
#
#   Debian 12 (libopencv-dev 4.6): the source does NOT compile unchanged. Checked with g++
#   12.2 (-fsyntax-only) against Debian's OpenCV 4.6.0 headers:
#     - opencv2/xfeatures2d.hpp does not exist: Debian's libopencv-contrib-dev ships no
#       xfeatures2d. Remove that include from the toolbox header and the
#       `using namespace cv::xfeatures2d` from the toolbox source, and delete the BRIEF, FREAK
#       and SURF branches of both description functions (global and grid); those three
#       descriptors are then unavailable in the original.
#     - The HOG descriptor is constructed with a bool where OpenCV 4 expects a
#       cv::HOGDescriptor::HistogramNormType; pass cv::HOGDescriptor::L2Hys (the only one)
#       explicitly. (Needed to compile; the LDB runs of this script do not use HOG.)
#     No other change is needed to compile: the LDB and D-LDB code and the rest compile
#     against 4.6 (SIFT resolves to cv::SIFT, in features2d since OpenCV 4.4), and no removed
#     C API header is involved (linking was not tried here). Then: apt-get install
#     build-essential cmake libopencv-dev; mkdir build && cd build && cmake .. && make.
#
# What the original expects, and how this script meets it:
#   - Its only argument is the path of the configuration file (OpenCV FileStorage YAML). It
#     reads every key; a key left out is an uninitialised value, so every key is written.
#   - Frames are read as Images_path + the identifier printed as %06d + "." + Images_format,
#     for identifiers Initial_image to Final_image - 1: Images_path is glued to the number
#     without a separator (hence the trailing slash) and no other naming is accepted (hence
#     the links).
#   - Txt_name and Png_name are opened relative to the working directory (hence the cd).
#   - It always exits with status 0; a failed read prints "... not valid or it does not
#     exist." and the matrix is still written, its unread rows left at their initial value
#     (hence the checks of its output).
#   - Its LDB keeps 1,384 of the 1,386 tests (173 bytes, chosen at random at every start);
#     this program's LDB has 256 bits unless Ldb_bits says otherwise. The table compares the
#     two programs as a user runs them with the same Config.txt, not equal descriptor lengths.
set -euo pipefail
export LC_ALL=C
me="vs_original.sh"
root="$(cd "$(dirname "$0")/.." && pwd)"

usage() {
  cat <<EOF
Usage: bench/vs_original.sh ORIGINAL_BINARY
Times the original OpenABLE's Test_OpenABLE (ORIGINAL_BINARY, built from its public source:
see the comments at the top of this script) against this project's Test_OpenABLE on the
Nordland trimmed frames (summer then winter, 3,576 frames, LDB, global 64x64 patch), both
writing the text matrix and the colour PNG, for L = 1, 10, 30 (5 alternated pairs each), then
peak memory at 7,152 frames (L = 10). Prints a Markdown table on stdout.
Environment: VS_ORIGINAL_RUNS (pairs per L, default 5), VS_ORIGINAL_LENGTHS (default "1 10 30"),
VS_ORIGINAL_MEMORY (0 skips the 7,152-frame run), VS_ORIGINAL_OURS (default
build/examples/Test_OpenABLE), VS_ORIGINAL_DATA (default ../shared/datasets/nordland_trimmed),
TMPDIR (temporary folder, removed on exit).
EOF
}
die() { echo "$me: $*" >&2; exit 1; }

case "${1:-}" in -h|--help) usage; exit 0 ;; esac
[ $# -ge 1 ] || die "no ORIGINAL_BINARY given: expected the path of the original OpenABLE's Test_OpenABLE (see --help)"
[ $# -eq 1 ] || die "expected exactly one argument, ORIGINAL_BINARY, got $# (see --help)"

abs_path() { (cd "$(dirname "$1")" && printf '%s/%s\n' "$(pwd)" "$(basename "$1")"); }
[ -e "$1" ] || die "ORIGINAL_BINARY '$1' not found: expected the original's Test_OpenABLE, built as the header of this script says"
[ -f "$1" ] && [ -x "$1" ] || die "ORIGINAL_BINARY '$1' is not an executable file: expected the original's Test_OpenABLE"
orig="$(abs_path "$1")"

ours="${VS_ORIGINAL_OURS:-$root/build/examples/Test_OpenABLE}"
[ -f "$ours" ] && [ -x "$ours" ] || die "this project's Test_OpenABLE not found at '$ours': expected a built tree (examples/setup.sh) or VS_ORIGINAL_OURS"
ours="$(abs_path "$ours")"
[ -x /usr/bin/time ] || die "/usr/bin/time not found: expected GNU time (Debian package 'time')"
command -v python3 > /dev/null || die "python3 not found: expected it on PATH (it makes the frame links)"

data="${VS_ORIGINAL_DATA:-$root/../shared/datasets/nordland_trimmed}"
[ -d "$data/summer" ] && [ -d "$data/winter" ] || die "Nordland frames not found: expected the folders $data/summer and $data/winter (see ../shared/datasets/README.md)"
data="$(cd "$data" && pwd)"
shopt -s nullglob
summer=("$data"/summer/*.png)
winter=("$data"/winter/*.png)
shopt -u nullglob
[ ${#summer[@]} -gt 0 ] && [ ${#summer[@]} -eq ${#winter[@]} ] || die "expected the same number (1788) of PNG frames in $data/summer and $data/winter, found ${#summer[@]} and ${#winter[@]}"

runs="${VS_ORIGINAL_RUNS:-5}"
lengths="${VS_ORIGINAL_LENGTHS:-1 10 30}"
memory="${VS_ORIGINAL_MEMORY:-1}"
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || die "VS_ORIGINAL_RUNS='$runs': expected a positive integer"
read -r -a lengths <<< "$lengths"
[ ${#lengths[@]} -gt 0 ] || die "VS_ORIGINAL_LENGTHS is empty: expected positive integers, e.g. \"1 10 30\""
for l in "${lengths[@]}"; do
  [[ "$l" =~ ^[1-9][0-9]*$ ]] || die "VS_ORIGINAL_LENGTHS contains '$l': expected positive integers, e.g. \"1 10 30\""
done
[[ "$memory" =~ ^[01]$ ]] || die "VS_ORIGINAL_MEMORY='$memory': expected 0 or 1"
[ "$orig" != "$ours" ] || echo "$me: note: ORIGINAL_BINARY is this project's Test_OpenABLE; the ratios only test the script" >&2

work="$(mktemp -d "${TMPDIR:-/tmp}/vs_original.XXXXXX")"
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Frames as the original names them: <folder>/%06d.png, links to the dataset's files.
# One process for all the links (a fork of ln per frame takes tens of seconds).
link_frames() {  # link_frames FOLDER FILE...
  local dir=$1
  shift
  mkdir "$dir"
  printf '%s\n' "$@" | python3 -c '
import os, sys
folder = sys.argv[1]
for i, target in enumerate(sys.stdin.read().splitlines()):
    os.symlink(target, os.path.join(folder, "%06d.png" % i))
' "$dir"
}
n1=$(( ${#summer[@]} + ${#winter[@]} ))
n2=$(( 2 * n1 ))
echo "$me: linking $n1 frames$([ "$memory" = 1 ] && echo " and $n2 frames") in $work" >&2
link_frames "$work/frames" "${summer[@]}" "${winter[@]}"
if [ "$memory" = 1 ]; then
  link_frames "$work/frames2" "${summer[@]}" "${winter[@]}" "${summer[@]}" "${winter[@]}"
fi
cat "${summer[@]}" "${winter[@]}" > /dev/null  # warm the page cache before the first timed run
load="$(cut -d' ' -f1-3 /proc/loadavg)"

write_config() {  # write_config FILE FRAMES_FOLDER N L
  cat > "$1" <<EOF
%YAML:1.0
# Written by bench/vs_original.sh: only the original OpenABLE's keys.
Frame_mode: 0
Images_path: "$2/"
Images_path_left: "$2/"
Images_path_right: "$2/"
Calibration_path: ""
Images_format: png
Video_path_1: ""
Video_path_2: ""
Initial_image: 0
Final_image: $3
Txt_name: similarity.txt
Png_name: similarity.png
Matrix_color: 7
Show_images: 0
Camera_type: 0
Description_type: 0
Patch_size: 64
Grid_x: 1
Grid_y: 1
Panoramas: 6
Illumination_invariance: 0
Alpha: 0.47
Image_descriptor: LDB
Image_sequences: $4
Threshold: -1
EOF
}

png_size() {  # png_size FILE: "WIDTH HEIGHT" from the IHDR chunk
  local b
  read -r -a b < <(od -An -tu1 -j16 -N8 "$1")
  [ ${#b[@]} -eq 8 ] || { echo "0 0"; return; }
  echo "$(( (b[0] << 24) | (b[1] << 16) | (b[2] << 8) | b[3] )) $(( (b[4] << 24) | (b[5] << 16) | (b[6] << 8) | b[7] ))"
}

# run_one WHO BINARY FRAMES N L: runs BINARY on a fresh Config.txt in its own folder, checks
# its outputs, deletes them and prints "WALL_SECONDS PEAK_RSS_KIB".
run_one() {
  local who=$1 bin=$2 frames=$3 n=$4 l=$5
  local dir="$work/run_$who" status=0 lines size wall rss
  rm -rf "$dir"
  mkdir "$dir"
  write_config "$dir/Config.txt" "$frames" "$n" "$l"
  (cd "$dir" && exec /usr/bin/time -f "%e %M" -o "$dir/time" "$bin" "$dir/Config.txt") \
    > "$dir/log" 2>&1 || status=$?
  local where="$who program ($bin), $n frames, L = $l"
  [ "$status" -eq 0 ] || die "$where exited with status $status, expected 0; its last line: $(tail -n 1 "$dir/log" | grep . || echo "(no output)")"
  if grep -q -e "not valid" -e "Couldn't open" -e "not available" -e "Choose a correct" "$dir/log"; then
    die "$where reported an error: $(grep -m 1 -e "not valid" -e "Couldn't open" -e "not available" -e "Choose a correct" "$dir/log")"
  fi
  [ -s "$dir/similarity.txt" ] || die "$where wrote no text matrix: expected $dir/similarity.txt"
  lines=$(wc -l < "$dir/similarity.txt")
  [ "$lines" -eq "$n" ] || die "$where wrote a text matrix of $lines rows: expected $n"
  [ -s "$dir/similarity.png" ] || die "$where wrote no PNG: expected $dir/similarity.png"
  size="$(png_size "$dir/similarity.png")"
  [ "$size" = "$n $n" ] || die "$where wrote a PNG of ${size/ /x} pixels: expected ${n}x$n"
  read -r wall rss < <(tail -n 1 "$dir/time")
  [[ "$wall" =~ ^[0-9.]+$ && "$rss" =~ ^[0-9]+$ ]] || die "$where: cannot read /usr/bin/time's output: $(cat "$dir/time")"
  rm -rf "$dir"
  echo "$wall $rss"
}

stats() {  # numbers on stdin -> "MEDIAN MIN MAX"
  sort -g | awk '{ a[NR] = $1 }
    END { m = (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2
          printf "%.6g %.6g %.6g\n", m, a[1], a[NR] }'
}
mib() { awk -v k="$1" 'BEGIN { printf "%.0f MiB", k / 1024 }'; }
secs() { awk -v s="$1" 'BEGIN { printf "%.2f s", s }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b < 0.01) b = 0.01; printf "%.4f\n", a / b }'; }
times_x() { awk -v r="$1" 'BEGIN { printf (r >= 10 ? "%.0fx" : "%.1fx"), r }'; }

rows=()
for l in "${lengths[@]}"; do
  : > "$work/ratios"; : > "$work/wall_o"; : > "$work/wall_u"
  peak_o=0; peak_u=0
  for ((r = 1; r <= runs; r++)); do
    res="$(run_one original "$orig" "$work/frames" "$n1" "$l")"; read -r wo ro <<< "$res"
    res="$(run_one ours "$ours" "$work/frames" "$n1" "$l")"; read -r wu ru <<< "$res"
    echo "$wo" >> "$work/wall_o"; echo "$wu" >> "$work/wall_u"
    ratio "$wo" "$wu" >> "$work/ratios"
    [ "$ro" -gt "$peak_o" ] && peak_o=$ro
    [ "$ru" -gt "$peak_u" ] && peak_u=$ru
    echo "$me: L = $l, pair $r/$runs: original $wo s, $ro KiB; ours $wu s, $ru KiB" >&2
  done
  read -r rmed rmin rmax < <(stats < "$work/ratios")
  read -r womed _ _ < <(stats < "$work/wall_o")
  read -r wumed _ _ < <(stats < "$work/wall_u")
  rows+=("| $l | $n1 | $runs | **$(times_x "$rmed")** ($(times_x "$rmin")-$(times_x "$rmax")) | $(secs "$womed") | $(secs "$wumed") | $(mib "$peak_o") | $(mib "$peak_u") |")
done
if [ "$memory" = 1 ]; then
  res="$(run_one original "$orig" "$work/frames2" "$n2" 10)"; read -r wo ro <<< "$res"
  res="$(run_one ours "$ours" "$work/frames2" "$n2" 10)"; read -r wu ru <<< "$res"
  echo "$me: $n2 frames, L = 10: original $wo s, $ro KiB; ours $wu s, $ru KiB" >&2
  rows+=("| 10 | $n2 | 1 | $(times_x "$(ratio "$wo" "$wu")") (one pair) | $(secs "$wo") | $(secs "$wu") | $(mib "$ro") | $(mib "$ru") |")
fi

cpu="$(lscpu 2>/dev/null | awk -F: '/^Model name/ { gsub(/^ +/, "", $2); print $2; exit }')"
family="$(lscpu 2>/dev/null | awk -F: '/^CPU family/ { gsub(/ /, "", $2); print $2; exit }')"
model="$(lscpu 2>/dev/null | awk -F: '/^Model:/ { gsub(/ /, "", $2); print $2; exit }')"
mem="$(awk '/^MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo)"
echo "*Machine:* ${cpu:-CPU model not reported} (family ${family:-?}, model ${model:-?}), $(nproc) cores, $mem; $(date +%Y-%m-%d); load average before the runs: $load."
echo
echo "Nordland trimmed, summer then winter as one sequence (links named %06d.png), LDB, global"
echo "64x64 patch, Threshold -1, both programs given the same old-style Config.txt and writing the"
echo "text matrix and the colour PNG; wall time and peak RSS of the whole process (GNU time);"
echo "pairs alternated (original, then ours); ratio = original / ours per pair."
echo "Original: $orig. Ours: $ours ($("$ours" --version 2>/dev/null | head -n 1), default Threads: all cores)."
echo
echo "| L | frames | pairs | time original / ours: median (min-max) | original, median | ours, median | peak RSS original | peak RSS ours |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
