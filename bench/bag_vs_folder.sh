#!/usr/bin/env bash
# Reading frames from a ROS 1 bag against reading them from their image folder: KITTI 00 frames
# 0-299 (the bag written by tests/rosbag/rosbag_test.cc, kept with OPENABLE_KEEP_TEST_FILES),
# described with the default settings; prints Test_OpenABLE's description time of each, best
# of three runs (docs/benchmarks.md, "Reading ROS bags").
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${OPENABLE_BUILD:-$root/build}
kitti=$root/../shared/datasets/kitti00_first1700/image_0
keep=$(mktemp -d)
trap 'rm -rf "$keep"' EXIT
OPENABLE_KEEP_TEST_FILES=1 TMPDIR=$keep "$build/tests/rosbag_tests" \
  --gtest_filter=RosBag.Kitti300FramesGiveTheFolderMatrixBitForBit > /dev/null
bag=$(find "$keep" -name kitti.bag | head -n 1)
[ -n "$bag" ] || { echo "no bag written (is ../shared/datasets there?)"; exit 1; }
best() {
  local best=""
  for _ in 1 2 3; do
    t=$("$build/examples/Test_OpenABLE" "$@" --set Npy_name= --set Png_name= --set Txt_name= \
          --set Ground_truth_type= 2>&1 | sed -n 's/^ *description *\([0-9.]*\) s.*/\1/p')
    if [ -z "$best" ] || python3 -c "import sys; sys.exit(0 if $t < $best else 1)"; then best=$t; fi
  done
  echo "$best"
}
folder=$(best --set "Images_path=$kitti" --set Final_image=300)
raw=$(best --set Frame_mode=3 --set "Bag_path=$bag" --set Bag_topic=/kitti/camera_gray_left/image_raw)
png=$(best --set Frame_mode=3 --set "Bag_path=$bag" --set Bag_topic=/kitti/camera_gray_left/image_png)
echo "description of 300 KITTI frames: folder (PNG files) $folder s, bag mono8 $raw s, bag CompressedImage (PNG) $png s"
