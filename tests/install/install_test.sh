#!/usr/bin/env bash
# CTest install.find_package_example (tests/CMakeLists.txt; docs/install.md): installs the build
# tree into a fresh prefix, builds examples/find_package against it as a user would, runs it
# on real frames, and runs the installed Test_OpenABLE with the build tree out of its reach.
#
#   install_test.sh BUILD_DIR SOURCE_DIR DATASETS_DIR BINDIR LIBDIR VERSION
#
# BINDIR and LIBDIR are CMAKE_INSTALL_BINDIR and CMAKE_INSTALL_LIBDIR (relative to the prefix).
# Every temporary file is in one folder outside the build tree (a program inside the build tree
# is allowed to use the build's modules: that would hide a broken lookup of the installed ones).
set -euo pipefail
build=$(cd "$1" && pwd -P)
source_dir=$(cd "$2" && pwd -P)
datasets=$3
bindir=$4
libdir=$5
version=$6
jobs=${OPENABLE_JOBS:-2}
unset OPENABLE_MODULE_PATH  # the programs must find their modules on their own

tmp=$(mktemp -d "${TMPDIR:-/tmp}/openable_install_test.XXXXXX")
tmp=$(cd "$tmp" && pwd -P)
if [ -z "${OPENABLE_KEEP_TEST_FILES:-}" ]; then
  trap 'rm -rf "$tmp"' EXIT
else
  echo "keeping $tmp"
fi
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
case "$tmp/" in
  "$build"/*) fail "the temporary folder $tmp is inside the build tree $build" ;;
esac
prefix=$tmp/prefix

echo "== cmake --install into $prefix"
cmake --install "$build" --prefix "$prefix" > "$tmp/install.log" || {
  cat "$tmp/install.log"
  fail "cmake --install failed"
}
for f in "$bindir/Test_OpenABLE" "$bindir/openable_evaluate" "$bindir/openable_snaps" \
         "$libdir/libOpenABLE.a" "$libdir/libopenable_io.a" "$libdir/libopenable_odometry.a" \
         "$libdir/openable/libopenable_oiio.so" "$libdir/openable/libopenable_video.so" \
         "$libdir/openable/libopenable_gui.so" \
         "$libdir/cmake/OpenABLE/OpenABLEConfig.cmake" \
         "$libdir/cmake/OpenABLE/OpenABLEConfigVersion.cmake" \
         "$libdir/cmake/OpenABLE/OpenABLETargets.cmake" \
         include/openable/OpenABLE/OpenABLE.h include/openable/OpenABLE/online/online.h \
         include/openable/descriptors/descriptor.h include/openable/config/config.h; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
# Nothing of the tests, benchmarks or fuzzers, and no header outside include/openable.
stray=$(cd "$prefix" && find . \( -name '*_tests' -o -name 'bench_*' -o -name '*fuzzer*' \
          -o -name '*test_support*' -o \( -name '*.h' ! -path './include/openable/*' \) \) -print)
[ -z "$stray" ] || fail "installed but should not be: $stray"

echo "== examples/find_package against the installation"
# Only this prefix: an OpenABLE installed elsewhere (or the build tree) must not be found.
cmake -S "$source_dir/examples/find_package" -B "$tmp/example" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF > "$tmp/configure.log" 2>&1 || {
  cat "$tmp/configure.log"
  fail "configuring examples/find_package failed"
}
found=$(sed -n 's/^OpenABLE_DIR:PATH=//p' "$tmp/example/CMakeCache.txt")
[ "$found" = "$prefix/$libdir/cmake/OpenABLE" ] ||
  fail "find_package(OpenABLE) found '$found', expected $prefix/$libdir/cmake/OpenABLE"
cmake --build "$tmp/example" -j"$jobs" > "$tmp/build.log" 2>&1 || {
  cat "$tmp/build.log"
  fail "building examples/find_package failed"
}
example=$tmp/example/openable_online
"$example" --help | grep -q "^Usage: openable_online" || fail "openable_online --help"

# Runs the example on folder $1 (expecting $2 frames, exclusion $3) with options $4...; checks
# the frame count and that every printed candidate is old enough.
run_example() {
  local folder=$1 expected=$2 exclusion=$3
  shift 3
  local out=$tmp/example_run.txt
  "$example" "$folder" --exclusion "$exclusion" "$@" > "$out" ||
    fail "openable_online $folder exited with status $?"
  grep -qx "frames: $expected" "$out" || {
    cat "$out"
    fail "openable_online $folder: expected 'frames: $expected'"
  }
  grep -q "^loops: [0-9]* accepted candidates in [0-9]* frames$" "$out" || fail "no loops line"
  grep -q "^latency per frame (AddFrame): mean [0-9.]* ms, 99th percentile [0-9.]* ms$" "$out" ||
    fail "no latency line"
  awk -v ex="$exclusion" '/^frame [0-9]+:/ {
      q = $2 + 0
      for (i = 3; i <= NF; i += 2) if ($i + 0 > q - ex) { print "too recent: " $0; bad = 1 }
    } END { exit bad }' "$out" || fail "a candidate closer than the exclusion"
  tail -n 3 "$out"
}

# The bundled sample as one sequence: 300 summer frames, then the same 300 places in winter, so
# that winter frame 300 + i can close a loop with summer frame i.
sample=$source_dir/examples/data/nordland_sample
mkdir "$tmp/nordland"
for season in summer winter; do
  for f in "$sample/$season"/*.png; do
    ln -s "$f" "$tmp/nordland/$season-$(basename "$f")"
  done
done
count=$(find "$tmp/nordland" -name '*.png' | wc -l)
[ "$count" -eq 600 ] || fail "expected 600 sample frames, found $count"
# A threshold looser than the default, so that some candidates are printed (and checked).
run_example "$tmp/nordland" 600 100 --sequence-length 5 --threshold 0.25
# KITTI 00 (1241 x 376) when the shared datasets are there: the first 300 frames.
kitti=$datasets/kitti00_first1700/image_0
if [ -d "$kitti" ]; then
  run_example "$kitti" 300 100 --max-frames 300
else
  echo "-- KITTI 00 skipped: $kitti absent"
fi

echo "== installed Test_OpenABLE"
program=$prefix/$bindir/Test_OpenABLE
"$program" --version | grep -qF "$version" || fail "Test_OpenABLE --version does not print $version"
# Image folders: PNG and JPEG are decoded by OpenCV (no module); TIFF needs the OpenImageIO
# module, which the installed program must load from the prefix, not from the build tree.
# The first 20 summer frames (images-00010.png to images-00200.png) in each format.
mkdir "$tmp/png" "$tmp/jpeg" "$tmp/tiff" "$tmp/out"
for i in $(seq 10 10 200); do
  ln -s "$sample/summer/$(printf 'images-%05d.png' "$i")" "$tmp/png/"
done
for format in jpeg:jpg tiff:tif; do
  oiiotool --frames 10-200x10 "$sample/summer/images-%05d.png" \
    -o "$tmp/${format%:*}/images-%05d.${format#*:}" || fail "oiiotool cannot write ${format%:*}"
done
for format in png jpeg tiff; do
  count=$(find "$tmp/$format" -name 'images-*' | wc -l)
  [ "$count" -eq 20 ] || fail "expected 20 $format frames, found $count"
done
run_installed() {  # $1: image folder, $2: output name; the rest: environment for the program
  local folder=$1 name=$2
  shift 2
  env "$@" "$program" --quiet --set Images_path="$folder" --set Images_path_2= \
    --set Image_sequences=5 --set Txt_name= --set Npy_name="$tmp/out/$name.npy" \
    --set Png_name= --set Ground_truth_type= --set Evaluation_name= \
    > "$tmp/out/$name.log" 2>&1
}
for format in png jpeg; do
  run_installed "$tmp/$format" "$format" || {
    cat "$tmp/out/$format.log"
    fail "installed Test_OpenABLE on a $format folder"
  }
  [ -s "$tmp/out/$format.npy" ] || fail "installed Test_OpenABLE wrote no matrix for $format"
done
run_installed "$tmp/tiff" tiff LD_DEBUG=files || {
  grep -v "^ *[0-9]*:" "$tmp/out/tiff.log"
  fail "installed Test_OpenABLE on a TIFF folder"
}
loaded=$(grep -o "file=[^ ]*libopenable_oiio\.so" "$tmp/out/tiff.log" | head -n 1 | cut -d= -f2)
[ "$loaded" = "$prefix/$libdir/openable/libopenable_oiio.so" ] ||
  fail "installed Test_OpenABLE loaded the OpenImageIO module from '$loaded', expected $prefix/$libdir/openable"
# The installed Python package (when the build made one) imports from the prefix and reads a
# TIFF through the prefix's OpenImageIO module, found three folders above the extension
# (<prefix>/lib/python3.X/dist-packages/openable/_openable.cpython-*.so).
python_dir=$(find "$prefix" -name '_openable.cpython-*.so' -printf '%h\n' 2> /dev/null | head -n 1)
if grep -q "^OPENABLE_BUILD_PYTHON:BOOL=ON" "$build/CMakeCache.txt" && [ -z "$python_dir" ]; then
  fail "the build made the Python package but cmake --install did not install its extension"
fi
if [ -n "$python_dir" ]; then
  python_dir=$(dirname "$python_dir")
  tiff=$(ls "$tmp/tiff"/* | head -n 1)
  (cd "$tmp" && LD_DEBUG=files PYTHONPATH="$python_dir" /usr/bin/python3 -c \
     "import openable, sys; a = openable.read_image(sys.argv[1]); assert a.ndim >= 2; print(openable.__file__)" \
     "$tiff" > "$tmp/out/python.log" 2>&1) || {
    grep -v "^ *[0-9]*:" "$tmp/out/python.log"
    fail "the installed Python module could not read a TIFF"
  }
  grep -q "^$python_dir/openable" "$tmp/out/python.log" ||
    fail "python imported openable from elsewhere than $python_dir"
  loaded=$(grep -o "file=[^ ]*libopenable_oiio\.so" "$tmp/out/python.log" | head -n 1 | cut -d= -f2)
  [ "$loaded" = "$prefix/$libdir/openable/libopenable_oiio.so" ] ||
    fail "the installed Python module loaded the OpenImageIO module from '$loaded', expected $prefix/$libdir/openable"
  echo "-- installed Python module: imports and reads TIFF with the prefix's module"
fi
# A copy of the program in a prefix without modules must fail and say where it looked: a
# program outside the build tree never falls back on the build's modules.
configured=$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$build/CMakeCache.txt")
if [ -e "$configured/$libdir/openable/libopenable_oiio.so" ]; then
  echo "-- lookup without installed modules skipped: $configured/$libdir/openable holds OpenABLE modules"
else
  mkdir -p "$tmp/bare/$bindir"
  cp "$program" "$tmp/bare/$bindir/"
  program=$tmp/bare/$bindir/Test_OpenABLE
  if run_installed "$tmp/tiff" bare; then
    fail "a Test_OpenABLE without installed modules read TIFF images (modules found elsewhere)"
  fi
  grep -q "libopenable_oiio.so\" cannot be loaded (searched $tmp/bare/$libdir/openable, " \
    "$tmp/out/bare.log" || {
    cat "$tmp/out/bare.log"
    fail "unexpected error of a Test_OpenABLE without installed modules"
  }
  if grep -qF "$build" "$tmp/out/bare.log"; then
    fail "an installed program searched the build tree: $(cat "$tmp/out/bare.log")"
  fi
fi
echo "== installation usable"
