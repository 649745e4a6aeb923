"""Runs the tutorial of docs/python.md as it is written: every ```python block, in order, in one
namespace, from the repository root (where the tutorial's relative paths start). Exit status 77
(CTest's "Skipped") when ../shared/datasets is absent, 1 when a block fails (naming its line).
"""
import os
import re
import sys
import time
import traceback
from pathlib import Path

SOURCE_DIR = Path(__file__).resolve().parents[2]


def blocks(markdown):
    """(first line number, code) of each ```python block."""
    out = []
    for m in re.finditer(r"^```python\n(.*?)^```", markdown, re.S | re.M):
        out.append((markdown.count("\n", 0, m.start()) + 2, m.group(1)))
    return out


def main():
    path = Path(sys.argv[1] if len(sys.argv) > 1 else SOURCE_DIR / "docs" / "python.md")
    datasets = SOURCE_DIR.parent / "shared" / "datasets"
    if not datasets.exists():
        print("dataset absent: %s; the tutorial is not run" % datasets)
        return 77
    code = blocks(path.read_text())
    if not code:
        print("%s: no ```python block" % path)
        return 1
    os.chdir(SOURCE_DIR)
    namespace = {"__name__": "__tutorial__"}
    start = time.monotonic()
    for line, source in code:
        print("--- %s:%d" % (path.name, line), flush=True)
        try:
            exec(compile(source, "%s:%d" % (path, line), "exec"), namespace)
        except Exception:
            traceback.print_exc()
            print("FAILED: the block at %s:%d" % (path, line))
            return 1
    print("tutorial: %d blocks ran in %.1f s" % (len(code), time.monotonic() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
