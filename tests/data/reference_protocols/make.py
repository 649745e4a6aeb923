#!/usr/bin/env python3
"""Expected figures of the VPR-Bench and VPR_Tutorial protocols, computed by their own code.

Run with Debian 12's numpy 1.24 and scikit-learn 1.2 (python3-numpy, python3-sklearn):

    python3 make.py VPR_BENCH_CHECKOUT VPR_TUTORIAL_CHECKOUT

where the checkouts are github.com/MubarizZaffar/VPR-Bench (commit 77ad30f3, MIT licence) and
github.com/stschubert/VPR_Tutorial (commit e0713093, GPL-3.0). Their code is imported from the
checkouts, never copied here: VPR-Bench's performance_comparison.py (compute_matches,
compute_precision_recall, compute_auc_PR, compute_extendedprecision, compute_RecallRateAtN)
and VPR_Tutorial's evaluation/metrics.py (createPR, recallAt100precision, recallAtK).

Writes, beside this script:
  hand_distances.npy      7 x 9 float32 distances (queries x references), no two equal in a row
  hand_ground_truth.npy   VPR-Bench's format: object array (7, 2), row q = [q, [true refs]]
                          (query 4 has no true reference; pickled by numpy's np.save)
  hand_gt_hard.npy        VPR_Tutorial's GThard: bool 9 x 7 (database x queries), the same pairs
  hand_gt_soft.npy        GTsoft: GThard plus two cells
  hand_gt.npz             GThard and GTsoft in one np.savez archive
  ties_distances.npy      6 x 8 float32 distances in steps of 1/8 (many equal values)
  ties_gt_hard.npy        its GThard (8 x 6)
  expected.json           the figures, per case and protocol
The real case uses the committed gardens_point_hog.npy (200 x 200, the normalised distance
block of an OpenABLE HOG run, Gardens Point day_left queries against day_right references)
and vpr_bench_gardens_point_ground_truth_new.npy (VPR-Bench's datasets/GardensPointWalking
file, MIT licence, Python 2 pickle), whose GThard is the same lists as a matrix.

Conventions: the similarity is S = -D (float32), VPR_Tutorial's S is its transpose (database x
queries). VPR-Bench's best match and score are numpy.argmax and max of a query's S row.
scikit-learn 1.2 returns the whole precision-recall curve; VPR-Bench ran under Python 2.7 with
scikit-learn <= 0.20, which stops the curve at the first point of full recall: "curve_020"
below drops the points past it (they change neither AUC, as recall stays 1 along them, nor EP).
"""
import json
import os
import sys
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def load_reference(vpr_bench, vpr_tutorial):
    # performance_comparison.py imports plotting modules it does not need for the metrics.
    for name in ("matplotlib", "matplotlib.pyplot", "create_datasetspecific_VPRperformance_summary"):
        module = types.ModuleType(name)
        module.use = lambda *a, **k: None
        module.create_datasetspecific_VPR_summary = None
        sys.modules[name] = module
    sys.modules["matplotlib"].pyplot = sys.modules["matplotlib.pyplot"]
    sys.path.insert(0, vpr_bench)
    sys.path.insert(0, vpr_tutorial)
    import performance_comparison as bench
    from evaluation import metrics as tutorial
    return bench, tutorial


def curve_020(precision, recall, matches, scores):
    """The curve of scikit-learn 0.20: scikit-learn 1.2's without the points past full recall."""
    from sklearn.metrics._ranking import _binary_clf_curve
    _, tps, _ = _binary_clf_curve(np.asarray(matches), np.asarray(scores))
    last = int(tps.searchsorted(tps[-1]))
    drop = len(tps) - 1 - last
    return precision[drop:], recall[drop:]


def vpr_bench_figures(bench, distances, gt_info):
    S = -distances
    retrieved = [int(np.argmax(row)) for row in S]
    scores = [row.max() for row in S]
    matches = bench.compute_matches(retrieved, gt_info)
    precision, recall = bench.compute_precision_recall(matches, scores)
    auc = float(bench.compute_auc_PR(precision, recall))
    ep = float(bench.compute_extendedprecision(precision, recall))
    # The R_P100 term of compute_extendedprecision.
    r_p100 = 0.0 if precision[-2] < 1 else float(recall[min(np.argwhere(precision == 1))][0])
    max_n = min(19, distances.shape[1])
    at_n = [float(bench.compute_RecallRateAtN(n, list(S), gt_info)) for n in range(1, max_n + 1)]
    p020, r020 = curve_020(precision, recall, matches, scores)
    return {"auc_pr": auc, "extended_precision": ep, "recall_at_100p": r_p100,
            "recall_at_n": at_n, "right_best_matches": int(np.sum(matches)),
            "precision": [float(v) for v in p020], "recall": [float(v) for v in r020]}


def vpr_tutorial_figures(tutorial, distances, gt_hard, gt_soft):
    S = np.ascontiguousarray((-distances).T)
    out = {}
    P, R = tutorial.createPR(S, gt_hard, gt_soft, matching="multi", n_thresh=100)
    out["precision_multi"] = [float(v) for v in P]
    out["recall_multi"] = [float(v) for v in R]
    out["auc_multi"] = float(np.trapz(P, R))
    out["recall_at_100p_multi"] = float(
        tutorial.recallAt100precision(S, gt_hard, gt_soft, matching="multi", n_thresh=100))
    if gt_soft is None:
        P, R = tutorial.createPR(S, gt_hard, None, matching="single", n_thresh=100)
        out["precision_single"] = [float(v) for v in P]
        out["recall_single"] = [float(v) for v in R]
        out["auc_single"] = float(np.trapz(P, R))
        out["recall_at_100p_single"] = float(
            tutorial.recallAt100precision(S, gt_hard, None, matching="single", n_thresh=100))
    # recallAtK fails for K above the database's size (its indexing does not broadcast):
    # None there.
    out["recall_at_k"] = [float(tutorial.recallAtK(S, gt_hard, K=k)) if k <= S.shape[0] else None
                          for k in (1, 5, 10)]
    return out


def object_ground_truth(lists):
    gt = np.empty((len(lists), 2), dtype=object)
    for q, refs in enumerate(lists):
        gt[q, 0] = q
        gt[q, 1] = list(refs)
    return gt


def hard_matrix(lists, references):
    m = np.zeros((references, len(lists)), dtype=bool)
    for q, refs in enumerate(lists):
        for r in refs:
            if r < references:  # VPR-Bench's lists may name references past the last
                m[r, q] = True
    return m


def main():
    bench, tutorial = load_reference(sys.argv[1], sys.argv[2])
    expected = {}

    # Hand-made: 7 queries, 9 references; distinct distances within each row.
    rng = np.random.default_rng(7)
    hand = (np.stack([rng.permutation(9) for _ in range(7)]).astype(np.float32) + 1) / 9.0
    hand += rng.uniform(0, 0.01, hand.shape).astype(np.float32)
    lists = [[0, 1], [2], [3, 4, 5], [8], [], [1], [6, 7]]
    # Queries 0, 2 and 6 find a true reference first, with different confidence.
    for q, r, d in ((0, 1, 0.02), (2, 4, 0.05), (3, 8, 0.2), (6, 7, 0.01)):
        hand[q, r] = d
    hand[3, 0] = 0.015  # query 3's best match is wrong and confident
    hand /= hand.max()
    hand = hand.astype(np.float32)
    np.save(os.path.join(HERE, "hand_distances.npy"), hand)
    gt_info = object_ground_truth(lists)
    np.save(os.path.join(HERE, "hand_ground_truth.npy"), gt_info, allow_pickle=True)
    hard = hard_matrix(lists, 9)
    soft = hard.copy()
    soft[4, 1] = True   # beside query 1's true reference 2... two references away
    soft[0, 3] = True
    np.save(os.path.join(HERE, "hand_gt_hard.npy"), hard)
    np.save(os.path.join(HERE, "hand_gt_soft.npy"), soft)
    np.savez(os.path.join(HERE, "hand_gt.npz"), GThard=hard, GTsoft=soft)
    expected["hand"] = {
        "vpr_bench": vpr_bench_figures(bench, hand, gt_info),
        "vpr_tutorial": vpr_tutorial_figures(tutorial, hand, hard, None),
        "vpr_tutorial_soft": vpr_tutorial_figures(tutorial, hand, hard, soft),
    }

    # Ties: distances in steps of 1/8; every query has a true reference. Only the figures that
    # do not depend on how ties are broken are compared (not R@N, R@K).
    ties = (rng.integers(2, 9, (6, 8)) / 8.0).astype(np.float32)
    ties[0, 0] = 1.0
    ties_lists = [[0], [1, 2], [2], [5], [4], [7]]
    # Right best matches at equal distances (1/8) for queries 1, 3 and 4, a wrong one for 2.
    ties[1, 2] = ties[3, 5] = ties[4, 4] = ties[2, 6] = 0.125
    np.save(os.path.join(HERE, "ties_distances.npy"), ties)
    ties_hard = hard_matrix(ties_lists, 8)
    np.save(os.path.join(HERE, "ties_gt_hard.npy"), ties_hard)
    vb = vpr_bench_figures(bench, ties, object_ground_truth(ties_lists))
    vt = vpr_tutorial_figures(tutorial, ties, ties_hard, None)
    for k in ("recall_at_n",):
        vb.pop(k)
    vt.pop("recall_at_k")
    expected["ties"] = {"vpr_bench": vb, "vpr_tutorial": vt}

    # Real: OpenABLE's HOG matrix of Gardens Point with VPR-Bench's own ground-truth file.
    real = np.load(os.path.join(HERE, "gardens_point_hog.npy"))
    real_gt = np.load(os.path.join(HERE, "vpr_bench_gardens_point_ground_truth_new.npy"),
                      allow_pickle=True, encoding="latin1")
    real_lists = [list(real_gt[q][1]) for q in range(real_gt.shape[0])]
    real_hard = hard_matrix(real_lists, real.shape[1])
    # No tie at the N-th place of a query (argpartition's choice among equals is unspecified).
    for row in -real:
        top = np.sort(row)[::-1][:20]
        assert len(np.unique(top)) == len(top), "a tie among the 20 most similar"
    expected["real"] = {
        "vpr_bench": vpr_bench_figures(bench, real, real_gt),
        "vpr_tutorial": vpr_tutorial_figures(tutorial, real, real_hard, None),
    }
    # The same with the true references widened by +-2 frames, as Tolerance 2 does.
    wide = [sorted({c for r in refs for c in range(r - 2, r + 3) if 0 <= c < real.shape[1]})
            for refs in real_lists]
    expected["real_tolerance_2"] = {
        "vpr_bench": vpr_bench_figures(bench, real, object_ground_truth(wide)),
        "vpr_tutorial": vpr_tutorial_figures(tutorial, real, hard_matrix(wide, real.shape[1]),
                                             None),
    }
    with open(os.path.join(HERE, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
