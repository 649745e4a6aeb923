#!/usr/bin/env bash
# The SNAPS figures of docs/benchmarks.md on real KITTI trajectories
# (../shared/datasets/kitti_trajectories): SO-DSO keyframe trajectories of sequences 00 and 06
# corrected with the ground-truth loop pairs, and KITTI 00 frames 0-1699 corrected with loops
# found by OpenABLE itself (LDB, L=1 matrix of kitti00_first1700) and by SNAPS's own search on
# the same images; the SO-DSO runs again with the pairs' frames that are not keyframes moved to
# the nearest keyframe within 1, 2 and 5 frames (Snaps_keyframe_tolerance). Prints
# openable_snaps' reports. Usage: bench/snaps_kitti.sh
source "$(dirname "$0")/common.sh"
data="$datasets"
kt="$data/kitti_trajectories"
snaps="$root/build/examples/openable_snaps"
able="$exe"
need_data "$kt"
out="${SNAPS_OUT:-$(mktemp -d)}"
mkdir -p "$out"

common=(--set Snaps_trajectory_format=kitti-id --set Snaps_world_to_camera=1 --quiet)
# SO-DSO keyframes of sequence $1 with its ground-truth loop pairs; more --set arguments follow.
so_dso() {
  local seq="$1" pairs="$kt/loop_pairs/groundTruth_KITTI00.pairs.csv"
  shift
  [ "$seq" = 06 ] && pairs="$kt/loop_pairs/kitti06GroundTruth.pairs.csv"
  "$snaps" "${common[@]}" --set Snaps_trajectory="$kt/vo_so_dso/seq$seq/poses_history_file.txt" \
    --set Snaps_ground_truth="$kt/poses/$seq.txt" --set Snaps_loops=pairs \
    --set Snaps_loops_file="$pairs" --set Snaps_drop_outside=1 "$@"
}
for seq in 00 06; do
  echo "=== KITTI $seq: SO-DSO keyframes, ground-truth loop pairs"
  so_dso "$seq" --set Snaps_output_name="$out/kitti$seq"
done
# Pairs at frames that are not keyframes (about 0.5 s a run; no files written).
for seq in 00 06; do
  for tolerance in 1 2 5; do
    echo "=== KITTI $seq: SO-DSO keyframes, ground-truth loop pairs, Snaps_keyframe_tolerance" \
      "$tolerance"
    so_dso "$seq" --set Snaps_keyframe_tolerance="$tolerance"
  done
done

# KITTI 00 frames 0-1699: the keyframes of that stretch, the ground truth of those frames.
awk '$1 < 1700' "$kt/vo_so_dso/seq00/poses_history_file.txt" > "$out/seq00_first1700.txt"
images="$data/kitti00_first1700/image_0"
echo "=== KITTI 00 frames 0-1699: loops found by OpenABLE (LDB, global 64x64, L=1)"
"$able" --quiet --set Images_path="$images" --set Images_path_2= --set Image_sequences=1 \
  --set Txt_name= --set Png_name= --set Threshold=-1 --set Ground_truth_type= \
  --set Npy_name="$out/kitti00_first1700.npy" > /dev/null
"$snaps" "${common[@]}" --set Snaps_trajectory="$out/seq00_first1700.txt" \
  --set Snaps_ground_truth="$data/kitti00_first1700/poses/00_first1700.txt" \
  --set Snaps_loops=matrix --set Snaps_loops_file="$out/kitti00_first1700.npy" \
  --set Snaps_output_name="$out/kitti00_first1700_openable"
echo "=== KITTI 00 frames 0-1699: SNAPS's own search on thumbnails"
"$snaps" "${common[@]}" --set Snaps_trajectory="$out/seq00_first1700.txt" \
  --set Snaps_ground_truth="$data/kitti00_first1700/poses/00_first1700.txt" \
  --set Snaps_loops=search --set Snaps_images="$images" \
  --set Snaps_output_name="$out/kitti00_first1700_search"

echo "=== KITTI 00 frames 0-1699 from the images: monocular odometry (scale from the"
echo "    ground truth's step lengths), loops found by OpenABLE on the same frames"
"$snaps" --quiet --set Snaps_odometry=mono --set Images_path="$images" \
  --set Odometry_calibration="$data/kitti00_first1700/calib.txt" --set Odometry_calibration_scale=0.5 \
  --set Snaps_ground_truth="$data/kitti00_first1700/poses/00_first1700.txt" \
  --set Snaps_loops=openable --set Snaps_output_name="$out/kitti00_first1700_chain"
echo "outputs in $out"
