#!/usr/bin/env python3
"""Compares two trees of outputs written by bench/same_outputs.sh (two builds, the same runs).

Every file is compared byte for byte; where two differ, text files are compared again with what
differs from run to run by nature masked: the time and latency members of JSON objects, the
"seconds" column of CSV files and of tables, durations written as "<number> s|ms|min", latency
summaries, and the folders the outputs were written to. JSON is compared parsed, so a change of
its formatting alone (spacing, number spelling, NaN written as null) is not a difference when the
values are equal. Usage: bench/compare_outputs.py OUT_A OUT_B (exit 0 when the trees agree)."""
import json
import math
import os
import re
import sys

TIME_KEY = re.compile(r"(seconds|^timings$|^latency$|_s$|^date$|^started$|^finished$)")
# The folders bench/same_outputs.sh wrote to (out_a, out_b, or any folder named same_outputs*).
OUT_FOLDER = re.compile(r"(/[^ \"]*)?/(out_[ab]|same_outputs)[^/ \"]*/")


def strip(v):
    """A JSON value with time members masked and NaN made null (as a JSON writer may spell it)."""
    if isinstance(v, dict):
        return {k: ("T" if TIME_KEY.search(k) else strip(x)) for k, x in v.items()}
    if isinstance(v, list):
        return [strip(x) for x in v]
    if isinstance(v, float) and math.isnan(v):
        return None
    if isinstance(v, str):
        return OUT_FOLDER.sub("OUT/", v)
    return v


def masked_lines(path):
    lines = open(path, errors="replace").read().split("\n")
    out, seconds_col = [], None
    for i, line in enumerate(lines):
        if path.endswith(".csv") and i == 0 and "seconds" in line.split(","):
            seconds_col = line.split(",").index("seconds")
        if seconds_col is not None and i > 0 and line:
            cells = line.split(",")
            if len(cells) > seconds_col:
                cells[seconds_col] = "T"
            line = ",".join(cells)
        if len(line) > 20000:  # an embedded image (the HTML report): compared as it is; the
            out.append(line)   # masks below would take minutes on a megabyte line
            continue
        line = re.sub(r"\b\d+(\.\d+)?(e-?\d+)? ?(s|ms|us|ns|min)\b", "T", line)
        line = re.sub(r"\b(min|q1|median|q3|max|mean) +[\d.]+", r"\1 T", line)
        line = OUT_FOLDER.sub("OUT/", line)
        # openable_sweep's table: each row ends with its seconds (and a '*' when it described).
        line = re.sub(r"^( +\d+ .*?) +\d+\.\d{3}( \*)?$", r"\1 T\2", line)
        out.append(line)
    return out


def same(fa, fb):
    if open(fa, "rb").read() == open(fb, "rb").read():
        return True
    if fa.endswith(".json"):
        try:
            return strip(json.load(open(fa))) == strip(json.load(open(fb)))
        except ValueError:
            pass
    if fa.endswith((".txt", ".csv", ".html", ".log", ".json")):
        ta, tb = masked_lines(fa), masked_lines(fb)
        for x, y in [(x, y) for x, y in zip(ta, tb) if x != y][:2]:
            print("    < " + x[:200] + "\n    > " + y[:200])
        return ta == tb
    return False


def files(root):
    return sorted(os.path.relpath(os.path.join(d, f), root)
                  for d, _, names in os.walk(root) for f in names)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = sys.argv[1], sys.argv[2]
    fa, fb = files(a), files(b)
    bad = 0
    for f in sorted(set(fa) | set(fb)):
        if f not in fa or f not in fb:
            print("only in %s: %s" % (a if f in fa else b, f))
            bad += 1
        elif not same(os.path.join(a, f), os.path.join(b, f)):
            print("differs: " + f)
            bad += 1
    print("%d files compared: %s" % (len(fa), "same" if bad == 0 else "%d DIFFERENT" % bad))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
