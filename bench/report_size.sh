#!/usr/bin/env bash
# The size of the HTML report (Report_name) of a Nordland-sized run: Nordland trimmed, winter
# against summer (1788 + 1788 frames), the across-conditions preset, aligned ground truth.
# Prints the page's size against the 20 MB target, what takes the bytes (the images by class,
# the explorer's embedded data), the run's export time (which includes the report) and the
# CPU, for docs/benchmarks.md. Exits 1 when the page is 20 MB or more.
# Usage: bench/report_size.sh [--set Key=Value ...]   (from anywhere; needs ../shared/datasets)
source "$(dirname "$0")/common.sh"
data="$datasets/nordland_trimmed"
prepare "$data" "$exe"
"$exe" "$root/config/presets/across_conditions.txt" --quiet \
  --set Images_path="$data/summer" --set Images_path_2="$data/winter" \
  --set Ground_truth_type=aligned --set Npy_name= --set Png_name= \
  --set Evaluation_name="$out/eval" --set Report_name="$out/report.html" "$@" > "$out/run"
grep -E "^  (total|export) " "$out/run"
echo "CPU: $(lscpu | sed -n 's/^Model name: *//p' | head -1)"
/usr/bin/python3 - "$out/report.html" <<'PY'
import re
import sys
from collections import Counter

text = open(sys.argv[1], encoding="utf-8").read()
size = len(text.encode())
parts, counts = Counter(), Counter()
for m in re.finditer(r"<img ([^>]*)>", text):
    kind = re.search(r'class="([^"]*)"', m.group(1))
    kind = "image " + (kind.group(1) if kind else "(no class)")
    parts[kind] += len(m.group(0))
    counts[kind] += 1
for m in re.finditer(r'<script type="[^"]*" id="([^"]*)">', text):
    end = text.index("</script>", m.end())
    key = "data " + re.sub(r"-\d+$", "", m.group(1))
    parts[key] += end - m.end()
    counts[key] += 1
print("report: %.2f MB (%d bytes), target < 20 MB" % (size / 1e6, size))
for key, n in parts.most_common():
    print("  %-28s %3d x  %6.2f MB" % (key, counts[key], n / 1e6))
print("  %-28s       %6.2f MB" % ("the rest", (size - sum(parts.values())) / 1e6))
sys.exit(0 if size < 20e6 else 1)
PY
