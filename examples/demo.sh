#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run the across-conditions
# preset (config/presets/across_conditions.txt) on the bundled Nordland sample: 300 winter
# frames matched against 300 summer frames, evaluated against their frame alignment. Outputs go
# to ./results: the matrix (results/nordland_sample.{npy,png}), the precision-recall figure and
# the ground truth drawn over the matrix (results/nordland_sample_eval_pr.png, _overlay.png), and
# all of it as one HTML page with the frames of the worst cases
# (results/nordland_sample_report.html).
# Extra arguments are passed to Test_OpenABLE (e.g. --set Image_sequences=20).
set -euo pipefail
cd "$(dirname "$0")/.."
bash examples/setup.sh
./build/examples/Test_OpenABLE config/presets/across_conditions.txt \
  --set Images_path=examples/data/nordland_sample/summer \
  --set Images_path_2=examples/data/nordland_sample/winter \
  --set Ground_truth_type=aligned \
  --set Npy_name=results/nordland_sample.npy \
  --set Png_name=results/nordland_sample.png \
  --set Evaluation_name=results/nordland_sample_eval \
  --set Report_name=results/nordland_sample_report.html \
  "$@"
