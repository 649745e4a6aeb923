#!/usr/bin/env bash
# examples/setup.sh: which Debian packages each choice installs (--print-packages, which
# installs nothing), and its refusal of unknown arguments. The README's first command must not
# pull in the test, Python, MPI, FAISS, ROS, Chromium or clang packages; --all must bring every
# one of them.
set -uo pipefail
setup="$1/examples/setup.sh"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
has() { [[ " $1 " == *" $2 "* ]]; }

demo=$(bash "$setup" --print-packages) || fail "--print-packages exited with $?"
for p in cmake g++ make ninja-build libopencv-dev libeigen3-dev libopenblas-dev libopenimageio-dev \
         openimageio-tools libpng-dev zlib1g-dev libdeflate-dev libjpeg-dev nlohmann-json3-dev; do
  has "$demo" "$p" || fail "the demo's packages lack $p: $demo"
done
optional=(libgtest-dev libgmock-dev libbenchmark-dev clang-format python3-numpy python3-dev pybind11-dev
          python3-pip python3-setuptools python3-wheel python3-venv chromium python3-websocket
          clang libclang-rt-14-dev libopenmpi-dev openmpi-bin libfaiss-dev librosbag-dev
          libsensor-msgs-dev)
for p in "${optional[@]}"; do
  has "$demo" "$p" && fail "the demo installs the optional $p"
done

all=$(bash "$setup" --all --print-packages) || fail "--all --print-packages exited with $?"
for p in $demo "${optional[@]}"; do
  has "$all" "$p" || fail "--all lacks $p"
done

some=$(bash "$setup" --with mpi,python --print-packages)
for p in libopenmpi-dev openmpi-bin python3-dev pybind11-dev python3-numpy libopencv-dev; do
  has "$some" "$p" || fail "--with mpi,python lacks $p"
done
for p in chromium libfaiss-dev libgtest-dev clang; do
  has "$some" "$p" && fail "--with mpi,python installs $p"
done

for args in "--with foo" "--frob" "--with"; do
  err=$(bash "$setup" $args --print-packages 2>&1 >/dev/null); status=$?
  [ "$status" -eq 2 ] || fail "setup.sh $args exited with $status, not 2"
  [ "$(printf '%s\n' "$err" | wc -l)" -eq 1 ] || fail "setup.sh $args: not one line: $err"
done

help=$(bash "$setup" --help) || fail "--help exited with $?"
for part in tests python mpi faiss rosbag chromium fuzz; do
  grep -q "^  $part " <<< "$help" || fail "--help does not describe the part $part"
done

# Every package named exists in Debian 12 (when apt has its lists).
if command -v apt-cache > /dev/null && [ -n "$(ls /var/lib/apt/lists/ 2>/dev/null | grep Packages)" ]; then
  for p in $all; do
    apt-cache show "$p" > /dev/null 2>&1 || fail "no Debian package $p"
  done
else
  echo "apt lists absent: the packages' existence is not checked"
fi

[ "$failures" -eq 0 ] && echo "setup.sh: all checks passed"
exit $((failures > 0))
