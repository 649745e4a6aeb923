#!/usr/bin/env bash
# Runs a fixed set of real-data runs of the programs and keeps every file they write, so that
# two builds (before and after a change that must not change results) can be compared file by
# file. Covers every descriptor; dense, bounded and approximate modes; panoramas, stereo,
# reverse sequences, illumination invariance, noise, side windows, fusion, verification, the
# auto mode; openable_evaluate; openable_sweep; openable_snaps with each loop source; a
# two-process mpirun run (when mpirun is there); the Python module (when it is built).
#
# Usage: bench/same_outputs.sh run BUILD_DIR OUT_DIR   (BUILD_DIR holds examples/Test_OpenABLE)
#        bench/same_outputs.sh compare OUT_A OUT_B     (exit 0 when every file is the same)
# The comparison (bench/compare_outputs.py) masks what differs from run to run by nature: times
# and latencies, and the folders the outputs were written to.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
data="$root/../shared/datasets"
# Debian's Python, with NumPy (python3-numpy), as the Python tests use it.
python="${OPENABLE_PYTHON:-/usr/bin/python3}"

if [ "${1:-}" = compare ] && [ $# -eq 3 ]; then
  exec "$python" "$root/bench/compare_outputs.py" "$2" "$3"
fi

[ "${1:-}" = run ] && [ $# -eq 3 ] || { sed -n 9,12p "$0" | cut -c3-; exit 2; }
build="$(cd "$2" && pwd)"; out="$3"
able="$build/examples/Test_OpenABLE"; evaluate="$build/examples/openable_evaluate"
sweep="$build/examples/openable_sweep"; snaps="$build/examples/openable_snaps"
[ -x "$able" ] || { echo "same_outputs.sh: $able not found (build first)" >&2; exit 1; }
[ -d "$data/nordland_trimmed" ] || { echo "same_outputs.sh: $data not found" >&2; exit 1; }
rm -rf "$out"; mkdir -p "$out"; out="$(cd "$out" && pwd)"
sample="$root/examples/data/nordland_sample"
gp="$data/gardens_point"; kitti="$data/kitti00_first1700"; sussex="$data/sussex_panoramas"

# One Test_OpenABLE run: NAME then --set arguments; writes NAME/ (matrix, PNG, matches,
# evaluation) and NAME/report.json (--json).
run() {
  local name="$1"; shift
  mkdir -p "$out/$name"
  (cd "$out/$name" && "$able" "$root/config/Config.txt" --quiet --json \
     --set Images_path="$sample/summer" --set Images_path_2="$sample/winter" \
     --set Txt_name= --set Npy_name=m.npy --set Png_name=m.png --set Evaluation_name=eval \
     "$@" > report.json 2> stderr.log) || echo "exit $?" >> "$out/$name/stderr.log"
}
for d in LDB BRIEF ORB BRISK FREAK SIFT HOG SAD; do  # D-LDB needs stereo: see the stereo runs
  run "descriptor_$d" --set Image_descriptor="$d" --set Png_threshold_name=t.png --set Txt_name=m.txt
done
run fusion --set Image_descriptor=HOG+LDB --set Fusion_weights=1,1
run contrast --set Image_descriptor=SAD --set Contrast_enhancement=1 --set Image_sequences=20
run reverse --set Sequence_direction=1 --set Sequence_partial=scale
run skip --set Sequence_partial=skip --set Match_score=ratio --set Match_threshold=0.9
run consistency --set Match_threshold=0.3 --set Match_consistency=1 --set Report_name=report.html
run illumination --set Images_path="$gp/day_left" --set Images_path_2="$gp/day_right" \
  --set Final_image=59 --set Illumination_invariance=1 --set Alpha=0.47
run noise --set Noise_gaussian=0.01 --set Noise_salt_pepper=0.01 --set Noise_seed=7
run side_window --set Side_window=1
run bounded --set Matrix_mode=2 --set Best_matches=5 --set Matches_name=matches.csv --set Npy_name= \
  --set Png_name= --set Ground_truth_type= --set Evaluation_name=
run bounded_ahead_band --set Matrix_mode=2 --set Band_width=40 --set Matches_name=matches.npy \
  --set Npy_name= --set Png_name= --set Ground_truth_type= --set Evaluation_name=
run approximate_ldb --set Approximate_search=1 --set Matches_name=matches.csv
run approximate_hog --set Image_descriptor=HOG --set Approximate_search=1 --set Approximate_engine=hnsw \
  --set Matches_name=matches.csv
run auto --set Auto=1 --set Report_name=report.html
run gardens_point --set Images_path="$gp/day_left" --set Images_path_2="$gp/day_right" \
  --set Image_descriptor=HOG --set Image_sequences=20 --set Match_consistency=1 --set Match_threshold=0.5
run nordland_stretch --set Images_path="$data/nordland_trimmed/summer" \
  --set Images_path_2="$data/nordland_trimmed/winter" --set Final_image=599 --set Image_sequences=20
run kitti_loops --set Images_path="$kitti/image_0" --set Images_path_2= --set Final_image=399 \
  --set Image_sequences=1 --set Ground_truth_type= --set Evaluation_name= --set Verification=1 \
  --set Verification_calibration="$kitti/calib.txt" --set Verification_calibration_scale=0.5 \
  --set Loops_name=loops.csv --set Threshold=-1
run panoramas --set Images_path="$sussex/training" --set Images_path_2="$sussex/test_infomax_binary" \
  --set Camera_type=2 --set Panoramas=8 --set Ground_truth_type= --set Evaluation_name= \
  --set Final_image=119
# Stereo: the EuRoC pairs with their calibration converted into the original's YAML (ML, MR,
# DL, DR, R, T: the right camera's pose in the left one's frame, from the two T_BS).
stereo="$out/stereo_input"; mkdir -p "$stereo/left" "$stereo/right"
cp "$data"/euroc_stereo_pairs/left_img_*.png "$stereo/left/"
cp "$data"/euroc_stereo_pairs/right_img_*.png "$stereo/right/"
"$python" - "$data/euroc_stereo_pairs" "$stereo/calibration.yaml" << 'EOF'
import re, sys
import numpy as np
def camera(path):
    text = open(path).read()
    t = [float(v) for v in re.search(r"T_BS:.*?data: \[(.*?)\]", text, re.S).group(1).split(",")]
    k = [float(v) for v in re.search(r"intrinsics: \[(.*?)\]", text).group(1).split(",")]
    d = [float(v) for v in re.search(r"distortion_coefficients: \[(.*?)\]", text).group(1).split(",")]
    return np.array(t).reshape(4, 4), k, d + [0.0]
(tl, kl, dl), (tr, kr, dr) = camera(sys.argv[1] + "/sensorLeft.yaml"), camera(sys.argv[1] + "/sensorRight.yaml")
right_from_left = np.linalg.inv(tr) @ tl
def mat(name, rows, cols, values):
    return "%s: !!opencv-matrix\n   rows: %d\n   cols: %d\n   dt: d\n   data: [ %s ]\n" % (
        name, rows, cols, ", ".join(repr(float(v)) for v in values))
k = lambda c: [c[0], 0, c[2], 0, c[1], c[3], 0, 0, 1]
open(sys.argv[2], "w").write("%YAML:1.0\n---\n" + mat("ML", 3, 3, k(kl)) + mat("MR", 3, 3, k(kr)) +
    mat("DL", 5, 1, dl) + mat("DR", 5, 1, dr) + mat("R", 3, 3, right_from_left[:3, :3].ravel()) +
    mat("T", 3, 1, right_from_left[:3, 3]) + "colormap: 2\nuse_log: 0\n")
EOF
for d in LDB D-LDB; do
  run "stereo_$d" --set Camera_type=1 --set Images_path_left="$stereo/left" \
    --set Images_path_right="$stereo/right" --set Images_path= --set Images_path_2= \
    --set Calibration_path="$stereo/calibration.yaml" --set Image_descriptor="$d" \
    --set Image_sequences=1 --set Ground_truth_type= --set Evaluation_name=
done

# A run over two processes writes what one process writes.
if command -v mpirun > /dev/null; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  mkdir -p "$out/mpirun"
  (cd "$out/mpirun" && mpirun --quiet --oversubscribe --bind-to none -np 2 "$able" \
     "$root/config/Config.txt" --quiet --set Images_path="$sample/summer" \
     --set Images_path_2="$sample/winter" --set Txt_name= --set Npy_name=m.npy --set Png_name=m.png \
     --set Evaluation_name=eval > report.txt 2> stderr.log) || echo "exit $?" >> "$out/mpirun/stderr.log"
fi

# openable_evaluate on two of the matrices above, with the report's frames.
mkdir -p "$out/evaluate"
(cd "$out/evaluate" && "$evaluate" --matrix "$out/descriptor_LDB/m.npy" --label LDB \
   --matrix "$out/descriptor_HOG/m.npy" --label HOG --reference-frames 300 --gt-type aligned \
   --output eval --report report.html --images "$sample/summer" --images-2 "$sample/winter" \
   > table.txt 2> stderr.log) || echo "exit $?" >> "$out/evaluate/stderr.log"

# openable_sweep with and without ground truth.
mkdir -p "$out/sweep"
(cd "$out/sweep" && "$sweep" "$root/config/Config.txt" --set Images_path="$sample/summer" \
   --set Images_path_2="$sample/winter" --vary Image_descriptor=LDB,HOG --vary Image_sequences=5,10 \
   --output gt > gt.txt 2> stderr.log &&
 "$sweep" "$root/config/Config.txt" --set Images_path="$sample/summer" \
   --set Images_path_2="$sample/winter" --set Ground_truth_type= --vary Image_descriptor=LDB,HOG \
   --rank-by agreement --output nogt > nogt.txt 2>> stderr.log) || echo "exit $?" >> "$out/sweep/stderr.log"

# openable_snaps with each source of loops on KITTI 00 frames 0-1699 (SO-DSO keyframes).
kt="$data/kitti_trajectories"
mkdir -p "$out/snaps"
awk '$1 < 1700' "$kt/vo_so_dso/seq00/poses_history_file.txt" > "$out/snaps/traj.txt"
common=(--quiet --set Snaps_trajectory_format=kitti-id --set Snaps_world_to_camera=1
        --set Snaps_trajectory="$out/snaps/traj.txt"
        --set Snaps_ground_truth="$kitti/poses/00_first1700.txt")
(cd "$out/snaps" &&
 "$snaps" --quiet --set Snaps_trajectory_format=kitti-id --set Snaps_world_to_camera=1 \
   --set Snaps_trajectory="$kt/vo_so_dso/seq00/poses_history_file.txt" \
   --set Snaps_ground_truth="$kt/poses/00.txt" --set Snaps_loops=pairs \
   --set Snaps_loops_file="$kt/loop_pairs/groundTruth_KITTI00.pairs.csv" --set Snaps_drop_outside=1 \
   --set Snaps_output_name=pairs > pairs.txt 2> stderr.log &&
 "$snaps" "${common[@]}" --set Snaps_loops=matrix \
   --set Snaps_loops_file="$out/kitti_loops/m.npy" --set Snaps_output_name=matrix > matrix.txt 2>> stderr.log &&
 "$snaps" "${common[@]}" --set Snaps_loops=search --set Snaps_images="$kitti/image_0" \
   --set Snaps_output_name=search > search.txt 2>> stderr.log &&
 "$snaps" "${common[@]}" --set Snaps_loops=openable --set Snaps_images="$kitti/image_0" \
   --set Image_sequences=1 --set Snaps_output_name=openable > openable.txt 2>> stderr.log) ||
  echo "exit $?" >> "$out/snaps/stderr.log"

# The Python module, when built: a matrix, an evaluation and the criteria.
if [ -d "$build/python/openable" ]; then
  mkdir -p "$out/python"
  PYTHONPATH="$build/python" "$python" - "$sample" "$out/python" << 'EOF' \
    > "$out/python/stdout.txt" 2> "$out/python/stderr.log" || echo "exit $?" >> "$out/python/stderr.log"
import sys
import numpy as np
import openable
sample, out = sys.argv[1], sys.argv[2]
summer = [openable.read_image(p) for p in openable.list_images(sample + "/summer")]
winter = [openable.read_image(p) for p in openable.list_images(sample + "/winter")]
for descriptor in ("LDB", "HOG"):
    rows = openable.describe_images(summer + winter, descriptor=descriptor)
    m = openable.distance_matrix(rows, sequence_length=10, traversal_starts=[0, len(summer)])
    np.save(out + "/" + descriptor + ".npy", m)
    print(openable.evaluate(m, aligned=True, reference_frames=len(summer), tolerance=2))
    print(openable.unsupervised_criteria(m, reference_frames=len(summer)))
EOF
fi
rm -rf "$stereo"
echo "same_outputs.sh: $(find "$out" -type f | wc -l) files in $out"
