#!/usr/bin/env bash
# Installs the Debian 12 packages OpenABLE needs (only those missing), then configures and
# builds it in ./build. examples/demo.sh runs it without options; tests/run_all.sh with --all.
#
#   bash examples/setup.sh                    what the demo runs
#   bash examples/setup.sh --with mpi,python  the programs plus the parts named
#   bash examples/setup.sh --all              every part: the whole build, tests included
#   bash examples/setup.sh --help
#   bash examples/setup.sh [--all | --with ...] --print-packages   the Debian packages, no more
#
# Without options it installs the packages the build cannot do without (the first list below,
# without the packages Debian only recommends) and builds the program the demo runs,
# Test_OpenABLE (`cmake --build build` adds openable_evaluate, openable_sweep and
# openable_snaps), not the tests, benchmarks or the Python module. The optional parts, each its packages and what they build:
#   tests     GoogleTest, Google Benchmark and clang-format: the test suite (its formatting
#             check among them) and benchmarks
#   python    pybind11, NumPy, the Python headers, pip/setuptools/wheel/venv: the module
#             openable and `pip install .` (docs/python.md)
#   mpi       Open MPI: runs over several processes (docs/distributed.md)
#   faiss     FAISS: approximate search (docs/matching.md)
#   rosbag    rosbag_storage and sensor_msgs: ROS 1 bags (docs/cameras.md)
#   chromium  Chromium and python3-websocket (its DevTools protocol): the tests that open the
#             HTML report (docs/output_formats.md)
#   fuzz      clang and libFuzzer: the fuzzers of tests/fuzz/ (docs/robustness.md)
# A part left out is reported by the configuration ("... not built") and a run that needs it
# says it is not built in. OPENABLE_JOBS sets the compile jobs (default: every CPU).
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { awk 'NR == 1 { next } /^#/ { sub(/^# ?/, ""); print; next } { exit }' "$0"; }

# What the configuration requires (CMakeLists.txt's find_package ... REQUIRED): OpenCV (its
# libopencv-dev depends on libopencv-contrib-dev, which holds ximgproc), Eigen, OpenImageIO,
# libpng, zlib, libdeflate (PNG writing, OpenABLE/io/image_codec.cc), libjpeg, nlohmann-json
# (header-only; every JSON document, OpenABLE/io/json.h), OpenBLAS (the float distance
# matrices, matching/blas.h).
# openimageio-tools too: Debian's OpenImageIO CMake package names its programs (iconvert, ...)
# as targets and stops the configuration when they are absent.
# ninja-build: Make builds a target's sources only once the targets it links are built, which
# with one unity group per library left one of two cores idle most of the time.
core=(cmake g++ make ninja-build libopencv-dev libeigen3-dev libopenblas-dev libopenimageio-dev
      openimageio-tools libpng-dev zlib1g-dev libdeflate-dev libjpeg-dev nlohmann-json3-dev)
all_parts=(tests python mpi faiss rosbag chromium fuzz)
part_packages() {
  case "$1" in
    tests) echo libgtest-dev libgmock-dev libbenchmark-dev clang-format ;;
    python) echo python3-numpy python3-dev pybind11-dev python3-pip python3-setuptools \
                 python3-wheel python3-venv ;;
    mpi) echo libopenmpi-dev openmpi-bin ;;
    faiss) echo libfaiss-dev ;;
    rosbag) echo librosbag-dev libsensor-msgs-dev ;;
    chromium) echo chromium python3-websocket ;;
    fuzz) echo clang libclang-rt-14-dev ;;
    *) return 1 ;;
  esac
}

parts=()
print_packages=0
while (($#)); do
  case "$1" in
    --all) parts=("${all_parts[@]}") ;;
    --with) [ $# -ge 2 ] || { echo "setup.sh: --with needs a list, e.g. --with mpi,python" >&2; exit 2; }
            IFS=, read -r -a more <<< "$2"; parts+=("${more[@]}"); shift ;;
    --with=*) IFS=, read -r -a more <<< "${1#--with=}"; parts+=("${more[@]}") ;;
    --print-packages) print_packages=1 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "setup.sh: unknown argument '$1' (--all, --with PART[,PART...], --print-packages, --help)" >&2
       exit 2 ;;
  esac
  shift
done
has_part() { local p; for p in "${parts[@]}"; do [ "$p" = "$1" ] && return 0; done; return 1; }

packages=()
for p in "${parts[@]}"; do
  list=$(part_packages "$p") || {
    echo "setup.sh: unknown part '$p' (parts: ${all_parts[*]})" >&2; exit 2; }
  read -r -a more <<< "$list"
  packages+=("${more[@]}")
done
if ((print_packages)); then
  echo "${core[@]}" "${packages[@]}"
  exit 0
fi

missing() {
  local p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || echo "$p"
  done
}
mapfile -t missing_core < <(missing "${core[@]}")
mapfile -t missing_parts < <(missing "${packages[@]}")
if ((${#missing_core[@]} + ${#missing_parts[@]})); then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  # The packages Debian only recommends (a desktop, Java bindings, systemd: about a hundred for
  # these) are not needed to build or run the programs.
  if ((${#missing_core[@]})); then
    echo "Installing missing Debian packages: ${missing_core[*]}"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
      "${missing_core[@]}"
  fi
  if ((${#missing_parts[@]})); then
    echo "Installing missing Debian packages (${parts[*]}): ${missing_parts[*]}"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing_parts[@]}"
  fi
fi

jobs=${OPENABLE_JOBS:-$(nproc)}
# A new build tree gets the programs only; an existing one keeps its settings (e.g. the tests of
# an earlier --all) unless a part asks for more.
# The libraries and programs as a unity build (CMakeLists.txt): 40% less compile time; Ninja.
settings=()
[ -f build/CMakeCache.txt ] ||
  settings+=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DOPENABLE_UNITY_BUILD=ON
             -DOPENABLE_BUILD_TESTS=OFF -DOPENABLE_BUILD_BENCHMARKS=OFF)
has_part tests && settings+=(-DOPENABLE_BUILD_TESTS=ON -DOPENABLE_BUILD_BENCHMARKS=ON)
has_part python && settings+=(-DOPENABLE_BUILD_PYTHON=ON)
cmake -S . -B build "${settings[@]}"
if has_part tests; then
  cmake --build build -j"$jobs"  # everything
else
  # openable_evaluate, openable_sweep and openable_snaps too with `cmake --build build` (or
  # any --with python).
  targets=(Test_OpenABLE)
  has_part python && targets+=(openable_python_package)
  # The run-time modules (those of mpi, faiss and rosbag when their packages are there) come
  # with the programs.
  cmake --build build -j"$jobs" --target "${targets[@]}"
fi
