#!/usr/bin/env python3
"""The L2 distance matrix of HOG-sized rows: OpenABLE's against numpy's on the same OpenBLAS.

numpy computes what OpenABLE computes (squared norms, one matrix product, |a|^2 + |b|^2 - 2ab,
clipped at 0, square root), in float32, for N rows of W floats against themselves (the symmetric
matrix of one traversal; numpy's a @ a.T is then a symmetric rank-k update, half the arithmetic,
as OpenABLE's lower triangle is). Each is timed in a process of its own, best and median of
--repeats runs after one warm-up, so that OpenABLE's choice of OpenBLAS's kernels (matching/blas.h)
does not change numpy's.

numpy runs twice: with the kernels OpenBLAS chooses on its own, as a user of numpy gets them, and
with OPENBLAS_CORETYPE naming the kernels OpenABLE runs (the same kernels on both sides).

Usage: bench/l2_vs_numpy.py [--rows 3576] [--width 1764] [--repeats 5]
Needs the build's Python module (build/python) and numpy.
"""
import argparse
import json
import os
import platform
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CHILD = r"""
import json, sys, time
import numpy as np
which, n, w, repeats, threads = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
a = np.random.default_rng(7).random((n, w), dtype=np.float32)

def numpy_l2(x):
    sq = np.einsum("ij,ij->i", x, x)
    d = sq[:, None] + sq[None, :] - 2.0 * (x @ x.T)
    np.maximum(d, 0, out=d)
    return np.sqrt(d, out=d)

if which == "openable":
    import openable
    run = lambda: openable.l2_distances(a, threads=threads)
    info = openable.blas_description()
else:
    run = lambda: numpy_l2(a)
    info = ""
first = run()
times = []
for _ in range(repeats):
    t = time.perf_counter()
    run()
    times.append(time.perf_counter() - t)
times.sort()
print(json.dumps({"best": times[0], "median": times[len(times) // 2], "info": info,
                  "sample": [float(first[1, 2]), float(first[n - 1, 0])]}))
"""


def cpu_model():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            if line.startswith("Model name:"):
                return line.split(":", 1)[1].strip()
    except (OSError, subprocess.CalledProcessError):
        pass
    return platform.processor() or "unknown CPU"


def run(which, args, env_extra):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.join(ROOT, "build", "python") + os.pathsep + env.get("PYTHONPATH", "")
    env.pop("OPENBLAS_CORETYPE", None)
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", CHILD, which, str(args.rows), str(args.width),
                          str(args.repeats), str(args.threads)],
                         capture_output=True, text=True, env=env)
    if out.returncode != 0:
        sys.exit(f"l2_vs_numpy.py: the {which} run failed: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads(out.stdout)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rows", type=int, default=3576)
    p.add_argument("--width", type=int, default=1764)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--threads", type=int, default=0, help="OpenABLE's threads (0 = all cores)")
    args = p.parse_args()
    ours = run("openable", args, {})
    kernels = ours["info"].split("kernels ")[1].split()[0] if "kernels " in ours["info"] else ""
    own = run("numpy", args, {})
    same = run("numpy", args, {"OPENBLAS_CORETYPE": kernels}) if kernels else None
    print(f"CPU: {cpu_model()} ({os.cpu_count()} cores)")
    print(f"OpenBLAS as OpenABLE runs it: {ours['info']}")
    print(f"L2 matrix of {args.rows} x {args.rows} rows of {args.width} floats "
          f"(best / median of {args.repeats}):")
    rows = [("OpenABLE l2_distances", ours), ("numpy, OpenBLAS's own kernels", own)]
    if same:
        rows.append((f"numpy, OPENBLAS_CORETYPE={kernels}", same))
    for name, r in rows:
        print(f"  {name:<40} {r['best']:.3f} s / {r['median']:.3f} s"
              f"   numpy/OpenABLE {r['median'] / ours['median']:.2f}")
    # The two agree within float rounding: a sanity check of what was timed.
    for x, y in zip(ours["sample"], own["sample"]):
        if abs(x - y) > 1e-3 * max(1.0, abs(y)):
            sys.exit(f"l2_vs_numpy.py: OpenABLE's {x} and numpy's {y} differ")


if __name__ == "__main__":
    main()
