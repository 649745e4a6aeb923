#!/usr/bin/env python3
"""How well each criterion computed without ground truth chooses among the auto mode's
candidates, on every pair of bench/auto.sh: for each pair and criterion, the AUC (ground truth,
ratio score) of the candidate the criterion ranks first, against the best AUC of the candidates.
Criteria: distinctiveness alone; consistency over partners one query apart (consecutive
answers, which share L - 1 sequence terms); consistency over independent partners (the
toolbox's, matching/agreement.h); their product; agreement (the toolbox's); and, for the
verdict, each pair's highest consistency (unrelated pairs must stay below
Auto_min_consistency). The figures are in docs/benchmarks.md, "Settings chosen from the data".

Usage: bench/auto.sh WORK (to make the night-like frames and parts in WORK), then
       PYTHONPATH=build/python python3 bench/criteria.py WORK
"""
import os
import sys

import numpy as np
import openable

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "datasets")
CANDIDATES = [(d, L) for d in ("HOG", "SIFT", "LDB", "HOG+LDB", "SAD+contrast")
              for L in (10, 20, 40)]


def pairs(work):
    gp, nl, night, parts = DATA + "/gardens_point", DATA + "/nordland_trimmed", work + "/night", \
        work + "/parts"
    aligned = [
        ("Nordland winter vs summer", nl + "/summer", nl + "/winter"),
        ("Gardens Point day_right vs day_left", gp + "/day_left", gp + "/day_right"),
        ("Gardens Point day_left vs day_right", gp + "/day_right", gp + "/day_left"),
        ("Nordland 0-299", parts + "/nord_s0", parts + "/nord_w0"),
        ("Nordland 600-899", parts + "/nord_w600", parts + "/nord_s600"),
        ("Nordland 1200-1499", parts + "/nord_s1200", parts + "/nord_w1200"),
        ("*GP night-like, same side", gp + "/day_right", night + "/gp_right_night"),
        ("*GP night-like", gp + "/day_left", night + "/gp_right_night"),
        ("*GP strong night-like", gp + "/day_left", night + "/gp_right_night_strong"),
        ("*GP extreme night-like", gp + "/day_left", night + "/gp_right_night_extreme"),
        ("*Nordland night-like, same season", nl + "/summer", night + "/nord_summer_night"),
        ("*Nordland night-like winter", nl + "/summer", night + "/nord_winter_night"),
        ("*Nordland strong night-like", nl + "/winter", night + "/nord_summer_night_strong"),
        ("*Nordland extreme night-like", nl + "/summer", night + "/nord_winter_night_extreme"),
    ]
    unrelated = [
        ("Nordland winter 1100-1699 vs summer 0-599", parts + "/nord_summer_a",
         parts + "/nord_winter_b"),
        ("Nordland winter 1100-1299 vs Gardens Point", gp + "/day_left", parts + "/nord_winter_c"),
        ("Nordland winter 1100-1699 vs Gardens Point", gp + "/day_left", parts + "/nord_winter_b"),
        ("KITTI 00 1500-1699 vs Gardens Point", gp + "/day_left", parts + "/kitti_qry"),
        ("Nordland winter 1100-1299 vs KITTI 00 40-260", parts + "/kitti_ref",
         parts + "/nord_winter_c"),
        ("Nordland winter 600-899 vs summer 0-299", parts + "/nord_s0", parts + "/nord_w600"),
        ("Nordland winter 1200-1499 vs summer 600-899", parts + "/nord_s600",
         parts + "/nord_w1200"),
        ("Gardens Point day_right vs RTAB-Map lap 1", parts + "/rtab_lap1", gp + "/day_right"),
    ]
    return aligned, unrelated


def single_frame(ref, qry):
    images = [openable.read_image(p) for p in openable.list_images(ref) + openable.list_images(qry)]
    n_ref = len(openable.list_images(ref))
    out = {}
    for d in ("HOG", "SIFT", "LDB", "SAD"):
        rows = openable.describe_images(images, descriptor=d)
        if d == "LDB":
            out[d] = openable.hamming_distances(rows)
        elif d == "SAD":
            out["SAD+contrast"] = openable.contrast_enhancement(
                openable.l1_distances(rows), window=10, col_starts=[0, n_ref])
        else:
            out[d] = openable.l2_distances(rows)
    out["HOG+LDB"] = out["HOG"] / out["HOG"].max() + out["LDB"] / out["LDB"].max()
    return out, n_ref


def consecutive_consistency(best):
    ok = (best[1:] >= 0) & (best[:-1] >= 0) & (np.abs(best[1:] - best[:-1] - 1) <= 3)
    return float(ok.mean())


def judge(ref, qry, truth):
    singles, n_ref = single_frame(ref, qry)
    rows = []
    for d, L in CANDIDATES:
        starts = [0, n_ref]
        m, _ = openable.normalize_by_max(openable.sequence_distances(
            singles[d], L, row_starts=starts, col_starts=starts))
        f = openable.unsupervised_criteria(m, reference_frames=n_ref, sequence_length=L)
        auc = (openable.evaluate(m, aligned=True, reference_frames=n_ref, tolerance=2,
                                 score="ratio").auc if truth else float("nan"))
        rows.append(dict(candidate="%s L=%d" % (d, L), auc=auc, D=f["distinctiveness"],
                         K1=consecutive_consistency(f["best"]), K=f["consistency"],
                         KxD=f["consistency"] * f["distinctiveness"], A=f["agreement"]))
    return rows


def main():
    work = sys.argv[1]
    aligned, unrelated = pairs(work)
    criteria = [("distinctiveness", "D"), ("consistency, consecutive queries", "K1"),
                ("consistency x distinctiveness", "KxD"), ("consistency", "K"),
                ("agreement", "A")]
    print("| pair | best AUC | " + " | ".join(c for c, _ in criteria) + " |")
    print("|---|---|" + "---|" * len(criteria))
    for name, ref, qry in aligned:
        rows = judge(ref, qry, True)
        best = max(r["auc"] for r in rows)
        cells = []
        for _, key in criteria:
            chosen = max(rows, key=lambda r: r[key])
            mark = " (-%.2f)" % (best - chosen["auc"]) if best - chosen["auc"] > 0.02 else ""
            cells.append("%.3f%s" % (chosen["auc"], mark))
        print("| %s | %.3f | %s |" % (name, best, " | ".join(cells)))
        sys.stdout.flush()
    print()
    print("| unrelated pair | highest consistency, consecutive queries | highest consistency | "
          "its candidate |")
    print("|---|---|---|---|")
    for name, ref, qry in unrelated:
        rows = judge(ref, qry, False)
        top = max(rows, key=lambda r: r["K"])
        print("| %s | %.3f | %.3f | %s |" % (name, max(r["K1"] for r in rows), top["K"],
                                            top["candidate"]))


if __name__ == "__main__":
    main()
