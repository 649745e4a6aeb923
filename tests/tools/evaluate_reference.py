#!/usr/bin/env python3
"""Independent reference for the two evaluation protocols of docs/evaluation.md.

Written separately from the C++ code (OpenABLE/evaluation/metrics.cc), with numpy and plain
loops, to check its figures on real matrices: per-query best match (AUC, R@100P, max F1,
R@1/5/10) and the ABLE-P cell protocol (thresholds k/99, vicinity, average precision).

  evaluate_reference.py --matrix M.npy [--reference-frames N] --exclusion E --tolerance T
      --vicinity V (--aligned | --pairs FILE [--base 0|1] [--max-col4 X])
      [--score distance|ratio] [--score-window W] [--compare openable.json]

NaN (or +inf) cells hold no value (Sequence_partial skip): never a candidate nor a rival.

With --compare, exits 1 when a figure of the JSON written by OpenABLE differs by more than
5e-4 (three decimals); prints both sets of figures either way.
"""
import argparse
import json
import sys

import numpy as np


def load_truth(args, queries, references, loop):
    """Set of (query row, reference column) pairs over the evaluated block."""
    truth = set()
    if args.aligned:
        for q in range(min(queries, references)):
            truth.add((q, q))
        return truth
    base = args.base
    with open(args.pairs) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith('#'):
                continue
            parts = s.replace(',', ' ').split()
            try:
                a, b = int(parts[0]) - base, int(parts[1]) - base
            except ValueError:
                continue  # a header line
            if args.max_col4 is not None and not float(parts[3]) < args.max_col4:
                continue
            if loop:
                a, b = max(a, b), min(a, b)
                if a == b:
                    continue
            truth.add((a, b))
    return truth


def per_query(block, truth, loop, exclusion, tolerance, score='distance', window=10):
    q_count, r_count = block.shape
    true_of = {}
    for (q, r) in truth:
        true_of.setdefault(q, []).append(r)
    best_d, correct, positive, rank_hits = [], [], [], {1: 0, 5: 0, 10: 0}
    queries, unanswered = 0, 0
    for q in range(q_count):
        end = r_count if not loop else max(0, q - exclusion + 1)
        if end == 0:
            continue
        queries += 1
        d = block[q, :end]
        t = [r for r in true_of.get(q, []) if r < end]
        pos = len(t) > 0
        positive.append(pos)
        finite = np.flatnonzero(np.isfinite(d))
        if finite.size == 0:
            unanswered += 1
            continue
        b = int(finite[np.argmin(d[finite])])  # the first of equal minima
        ok = pos and any(abs(b - r) <= tolerance for r in t)
        if score == 'ratio':
            rivals = finite[np.abs(finite - b) > window]
            rival = float(d[rivals].min()) if rivals.size else 0.0
            value = float(d[b]) / rival if rival > 0 else 1.0
        else:
            value = float(d[b])
        best_d.append(np.float32(value))
        correct.append(ok)
        if pos:
            order = finite[np.argsort(d[finite], kind='stable')]
            for n in rank_hits:
                if any(abs(int(c) - r) <= tolerance for c in order[:n] for r in t):
                    rank_hits[n] += 1
    best_d = np.array(best_d, dtype=np.float32)
    correct = np.array(correct, dtype=bool)
    p_count = int(np.sum(positive))
    auc, r100, f1max, f1thr, prev_r = 0.0, 0.0, 0.0, 0.0, 0.0
    for thr in np.unique(best_d):
        acc = best_d <= thr
        tp = int(np.sum(acc & correct))
        fp = int(np.sum(acc & ~correct))
        p = tp / (tp + fp)
        r = tp / p_count if p_count else 0.0
        auc += p * (r - prev_r)
        prev_r = r
        if fp == 0 and tp > 0:
            r100 = r
        f1 = 2 * p * r / (p + r) if p + r > 0 else 0.0
        if f1 > f1max:
            f1max, f1thr = f1, float(thr)
    return {
        'auc': auc, 'recall_at_100p': r100, 'max_f1': f1max, 'max_f1_threshold': f1thr,
        'recall_at_1': rank_hits[1] / p_count if p_count else 0.0,
        'recall_at_5': rank_hits[5] / p_count if p_count else 0.0,
        'recall_at_10': rank_hits[10] / p_count if p_count else 0.0,
        'queries': queries, 'positive_queries': p_count, 'unanswered_queries': unanswered,
    }


def shifted(a, dy, dx, fill):
    """a moved by (dy, dx): out[y, x] = a[y - dy, x - dx], `fill` where that is outside."""
    out = np.full(a.shape, fill, dtype=a.dtype)
    h, w = a.shape
    ys, yd = (slice(0, h - dy), slice(dy, h)) if dy >= 0 else (slice(-dy, h), slice(0, h + dy))
    xs, xd = (slice(0, w - dx), slice(dx, w)) if dx >= 0 else (slice(-dx, w), slice(0, w + dx))
    out[yd, xd] = a[ys, xs]
    return out


def able_p(block, truth, loop, exclusion, vicinity):
    q_count, r_count = block.shape
    rows, cols = np.indices(block.shape)
    cand = np.ones(block.shape, dtype=bool) if not loop else cols <= rows - exclusion
    gt = np.zeros(block.shape, dtype=bool)
    for (q, r) in truth:
        if 0 <= q < q_count and 0 <= r < r_count and cand[q, r]:
            gt[q, r] = True
    values = np.where(cand, block.astype(np.float64), np.inf)
    near = np.zeros(block.shape, dtype=bool)
    nearest = np.full(block.shape, np.inf)
    for dy in range(-vicinity, vicinity + 1):
        for dx in range(-vicinity, vicinity + 1):
            near |= shifted(gt, dy, dx, False)
            nearest = np.minimum(nearest, shifted(values, dy, dx, np.inf))
    t_count = int(gt.sum())
    cand_values = values[cand]
    cand_near = near[cand]
    gt_nearest = nearest[gt]
    ap, prev_r = 0.0, 0.0
    for k in range(100):
        theta = k / 99
        det = cand_values < theta
        n = int(det.sum())
        tp = int((det & cand_near).sum())
        p = tp / n if n else 1.0
        r = int((gt_nearest < theta).sum()) / t_count if t_count else 0.0
        ap += p * (r - prev_r)
        prev_r = r
    return {'average_precision_percent': 100 * ap, 'truth_cells': t_count,
            'candidate_cells': int(cand.sum())}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--matrix', required=True)
    ap.add_argument('--reference-frames', type=int, default=0)
    ap.add_argument('--exclusion', type=int, default=100)
    ap.add_argument('--tolerance', type=int, default=2)
    ap.add_argument('--vicinity', type=int, default=7)
    ap.add_argument('--aligned', action='store_true')
    ap.add_argument('--pairs')
    ap.add_argument('--base', type=int, default=0)
    ap.add_argument('--max-col4', type=float)
    ap.add_argument('--score', choices=['distance', 'ratio'], default='distance')
    ap.add_argument('--score-window', type=int, default=10)
    ap.add_argument('--compare')
    args = ap.parse_args()

    m = np.load(args.matrix).astype(np.float32)
    m[~np.isfinite(m)] = np.inf  # a cell without a value
    top = m[np.isfinite(m)].max() if np.isfinite(m).any() else 0
    m = m / top if top > 0 else m
    if m.shape[0] != m.shape[1]:
        block, loop = m, False
    elif args.reference_frames > 0:
        n = args.reference_frames
        block, loop = m[n:, :n], False
    else:
        block, loop = m, True
    truth = load_truth(args, block.shape[0], block.shape[1], loop)
    ours = {'per_query': per_query(block, truth, loop, args.exclusion, args.tolerance,
                                   args.score, args.score_window),
            'able_p': able_p(block, truth, loop, args.exclusion, args.vicinity)}
    print('reference:', json.dumps(ours, indent=1))
    if not args.compare:
        return 0
    with open(args.compare) as f:
        theirs = json.load(f)['runs'][0]
    bad = []
    for section in ours:
        for key, value in ours[section].items():
            other = theirs[section][key]
            if abs(float(other) - float(value)) > 5e-4:
                bad.append(f'{section}.{key}: OpenABLE {other} vs reference {value}')
    for b in bad:
        print('MISMATCH', b)
    print('agree to 3 decimals' if not bad else f'{len(bad)} figures differ')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
