#!/usr/bin/env bash
# The README's first command: install what is missing, build, and run Test_OpenABLE on the
# bundled Nordland sample (300 summer + 300 winter frames). Outputs go to ./results.
set -euo pipefail
cd "$(dirname "$0")/.."
bash examples/setup.sh
./build/examples/Test_OpenABLE config/Config.txt "$@"
