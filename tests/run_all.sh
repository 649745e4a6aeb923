#!/usr/bin/env bash
# The README's second command (and the whole of .ci/run): install what is missing, build,
# and run every test with CTest. Tests that need ../shared/datasets skip with a message when
# it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
bash examples/setup.sh
cd build
ctest --output-on-failure -j"${OPENABLE_JOBS:-$(nproc)}" --timeout 1200
