#!/usr/bin/env bash
# Installs the Debian 12 packages OpenABLE needs (only those missing), then configures and
# builds it in ./build. Used by examples/demo.sh and tests/run_all.sh. clang and
# libclang-rt-14-dev (libFuzzer) are only for the fuzzers of tests/fuzz/ (docs/robustness.md);
# python3-dev and pybind11-dev for the Python module, python3-pip, -setuptools, -wheel and
# -venv for pip install . (docs/python.md); chromium to open the HTML report in the tests
# (docs/output_formats.md); librosbag-dev and libsensor-msgs-dev for ROS 1 bags
# (docs/cameras.md); Open MPI for runs over several processes
# (docs/distributed.md) and FAISS for approximate search (docs/matching.md). nlohmann-json3-dev
# (header-only) writes every JSON document (OpenABLE/io/json.h).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake g++ make pkg-config libopencv-dev libopencv-contrib-dev libeigen3-dev
          libpng-dev zlib1g-dev libjpeg-dev nlohmann-json3-dev
          libopenimageio-dev openimageio-tools libgtest-dev libgmock-dev libbenchmark-dev
          python3-numpy python3-dev pybind11-dev python3-pip python3-setuptools python3-wheel
          python3-venv chromium clang libclang-rt-14-dev
          libopenmpi-dev openmpi-bin libfaiss-dev librosbag-dev libsensor-msgs-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "Installing missing Debian packages: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
fi

jobs=${OPENABLE_JOBS:-$(nproc)}
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
