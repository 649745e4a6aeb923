"""openable.evaluate with the protocols of VPR-Bench and VPR_Tutorial: the figures their own
code computes on the same matrices (tests/data/reference_protocols/expected.json, made by
make.py there), from a ground-truth file and from NumPy arrays, and the table of every
protocol."""
import json
import math
import unittest

import numpy as np

import openable
from support import SOURCE_DIR

DATA = SOURCE_DIR / "tests" / "data" / "reference_protocols"
EXPECTED = json.loads((DATA / "expected.json").read_text())


class ReferenceProtocols(unittest.TestCase):
    def assertFigure(self, actual, expected, what):
        if expected is None:
            self.assertTrue(math.isnan(actual), "%s: %r" % (what, actual))
        else:
            self.assertAlmostEqual(actual, expected, delta=1e-12, msg=what)

    def assertFigures(self, actual, expected, what):
        self.assertEqual(len(actual), len(expected), what)
        for i, (a, e) in enumerate(zip(actual, expected)):
            self.assertFigure(a, e, "%s[%d]" % (what, i))

    def test_vpr_bench_file_and_real_matrix(self):
        m = np.load(DATA / "gardens_point_hog.npy")
        r = openable.evaluate(m, truth_file=str(DATA / "vpr_bench_gardens_point_ground_truth_new.npy"),
                              truth_type="vpr_bench", layout="query_reference", tolerance=0,
                              protocol="all")
        e = EXPECTED["real"]["vpr_bench"]
        for key in ("auc_pr", "extended_precision", "recall_at_100p"):
            self.assertFigure(r.vpr_bench[key], e[key], key)
        self.assertFigures(r.vpr_bench["recall_at_n"], e["recall_at_n"], "recall_at_n")
        self.assertFigures(r.vpr_bench["precision"], e["precision"], "precision")
        t = EXPECTED["real"]["vpr_tutorial"]
        self.assertFigure(r.vpr_tutorial["auc_multi"], t["auc_multi"], "auc_multi")
        self.assertFigure(r.vpr_tutorial["auc_single"], t["auc_single"], "auc_single")
        self.assertFigures([r.vpr_tutorial["recall_at_k"][k] for k in (1, 5, 10)],
                           t["recall_at_k"], "recall_at_k")
        table = r.table()
        for protocol in ("openable", "vpr_bench", "vpr_tutorial"):
            self.assertIn("python             " + protocol, table)
        self.assertIn('"vpr_bench": {', r.to_json())

    def test_tutorial_matrices_as_numpy_arrays(self):
        # VPR_Tutorial's GThard and GTsoft are database x queries: evaluate takes queries x
        # references, their transposes.
        d = np.load(DATA / "hand_distances.npy")
        hard = np.load(DATA / "hand_gt_hard.npy")
        soft = np.load(DATA / "hand_gt_soft.npy")
        r = openable.evaluate(d, truth_matrix=hard.T, truth_soft_matrix=soft.T,
                              layout="query_reference", tolerance=0, protocol="vpr_tutorial")
        e = EXPECTED["hand"]["vpr_tutorial_soft"]
        self.assertTrue(r.vpr_tutorial["soft_ground_truth"])
        self.assertNotIn("auc_single", r.vpr_tutorial)
        self.assertFigure(r.vpr_tutorial["auc_multi"], e["auc_multi"], "auc_multi")
        self.assertFigures(r.vpr_tutorial["precision_multi"], e["precision_multi"], "precision")
        self.assertIsNone(r.vpr_bench)
        # The same from the .npz file.
        f = openable.evaluate(d, truth_file=str(DATA / "hand_gt.npz"), truth_type="vpr_tutorial",
                              layout="query_reference", tolerance=0, protocol="vpr_tutorial")
        self.assertEqual(f.vpr_tutorial["auc_multi"], r.vpr_tutorial["auc_multi"])

    def test_bad_protocol_names_the_argument(self):
        d = np.load(DATA / "hand_distances.npy")
        with self.assertRaises(ValueError) as caught:
            openable.evaluate(d, aligned=False, truth_matrix=np.zeros(d.shape), protocol="mAP",
                              layout="query_reference")
        self.assertTrue(str(caught.exception).startswith('protocol: "mAP" is not valid'),
                        str(caught.exception))


if __name__ == "__main__":
    unittest.main()
