#!/usr/bin/env bash
# The time of `pip install --no-build-isolation .` from a fresh clone into a clean virtual
# environment (python3 -m venv --system-site-packages), then of the tutorial of docs/python.md
# run in it (docs/benchmarks.md, "Installing with pip"). Offline; compiles with OPENABLE_JOBS
# (default: every CPU). Prints the seconds of each step.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git clone -q "$root" "$work/clone"
start=$(date +%s.%N)
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
venv=$(date +%s.%N)
(cd "$work/clone" && "$work/venv/bin/pip" install -q --no-build-isolation . > "$work/pip.log" 2>&1) ||
  { tail -n 30 "$work/pip.log"; exit 1; }
installed=$(date +%s.%N)
(cd "$root" && env -u PYTHONPATH "$work/venv/bin/python" tests/python/run_tutorial.py docs/python.md |
  tail -n 1)
done_at=$(date +%s.%N)
/usr/bin/python3 -c 'import sys, os; a, b, c, d = map(float, sys.argv[1:5]); print("venv %.1f s, pip install %.1f s, tutorial %.1f s, total %.1f s (%d CPUs, OPENABLE_JOBS=%s)" % (b - a, c - b, d - c, d - a, os.cpu_count(), os.environ.get("OPENABLE_JOBS", "all")))' \
  "$start" "$venv" "$installed" "$done_at"
