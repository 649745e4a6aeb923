#!/usr/bin/env python3
"""The three rules for sequence cells at a traversal's start (Sequence_partial scale, skip,
ahead) on every shared dataset with two traversals, and on KITTI 00 and the RTAB-Map sample as
loop closure: R@1, AUC and R@100P (ratio score) and how often a best match falls on the first
L - 1 reference frames, where the scaled cells sit (an attractor draws more than its share).

Usage: PYTHONPATH=build/python python3 bench/sequence_edges.py [night_folder]
(night_folder: the output folder of bench/auto.sh's night-like frames, for the synthetic
day/night pairs; without it only the real pairs are measured). Prints Markdown tables; the
figures are in docs/benchmarks.md, "Sequence edges".
"""
import os
import sys

import numpy as np
import openable

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "datasets")
RULES = ("scale", "skip", "ahead")


def rows(folder, descriptor):
    images = [openable.read_image(p) for p in openable.list_images(folder)]
    return openable.describe_images(images, descriptor=descriptor)


def single(ref, qry, descriptor):
    r = np.vstack([rows(ref, descriptor), rows(qry, descriptor)])
    if descriptor == "SAD":
        d = openable.l1_distances(r)
        return openable.contrast_enhancement(d, window=10, col_starts=[0, len(r) // 2])
    return openable.l2_distances(r) if r.dtype == np.float32 else openable.hamming_distances(r)


def two_traversals(name, ref, qry, descriptors=("HOG", "LDB", "SIFT", "SAD"), lengths=(10, 40)):
    n_ref = len(openable.list_images(ref))
    out = []
    for descriptor in descriptors:
        d = single(ref, qry, descriptor)
        starts = [0, n_ref]
        for L in lengths:
            for rule in RULES:
                m, _ = openable.normalize_by_max(openable.sequence_distances(
                    d, L, row_starts=starts, col_starts=starts, partial=rule))
                r = openable.evaluate(m, aligned=True, reference_frames=n_ref, tolerance=2,
                                      score="ratio")
                block = m[n_ref:, :n_ref]
                best, _, _ = openable.best_matches(np.ascontiguousarray(block), score="ratio")
                answered = best >= 0
                early = np.mean(best[answered] < L - 1) if answered.any() else 0.0
                out.append((name, descriptor + ("+contrast" if descriptor == "SAD" else ""), L,
                            rule, r.recall_at_1, r.auc, r.recall_at_100p, r.unanswered_queries,
                            early, (L - 1) / n_ref))
    return out


def main():
    night = sys.argv[1] if len(sys.argv) > 1 else None
    pairs = [("Nordland winter vs summer", DATA + "/nordland_trimmed/summer",
              DATA + "/nordland_trimmed/winter"),
             ("Gardens Point day_right vs day_left", DATA + "/gardens_point/day_left",
              DATA + "/gardens_point/day_right")]
    if night:
        pairs += [("Gardens Point night-like day_right vs day_left (synthetic)",
                   DATA + "/gardens_point/day_left", night + "/gp_right_night"),
                  ("Nordland night-like winter vs summer (synthetic)",
                   DATA + "/nordland_trimmed/summer", night + "/nord_winter_night")]
    print("| data | descriptor | L | rule | R@1 | AUC | R@100P | unanswered | best matches on "
          "the first L-1 references (their share of the references) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, ref, qry in pairs:
        for row in two_traversals(name, ref, qry):
            print("| %s | %s | %d | %s | %.3f | %.3f | %.3f | %d | %.3f (%.3f) |" % row)
        sys.stdout.flush()


if __name__ == "__main__":
    main()
