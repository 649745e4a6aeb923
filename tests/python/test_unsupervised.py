"""openable.unsupervised_criteria against the definitions written out with NumPy, evaluate's
accept_consistency against a hand-worked example, and openable.sweep ranked without ground
truth against openable_sweep, on the bundled sample."""
import unittest

import numpy as np

import openable
from support import SAMPLE, SOURCE_DIR, TempDirTestCase, read_json, run


def windows(q, L, ahead):
    end = L - 1 if ahead and q < L - 1 else q
    return max(0, end - L + 1), end


def brute_criteria(block, L, window=10, ahead=True):
    """docs/evaluation.md, "Without ground truth", in NumPy and loops."""
    nq, nr = block.shape
    best = np.full(nq, -1)
    margin = 0.0
    for q in range(nq):
        row = block[q]
        finite = np.isfinite(row)
        if not finite.any():
            continue
        best[q] = int(np.argmin(np.where(finite, row, np.inf)))
        far = finite & (np.abs(np.arange(nr) - best[q]) > window)
        rival = row[far].min() if far.any() else np.inf
        ratio = row[best[q]] / rival if np.isfinite(rival) and rival > 0 else 1.0
        margin += 1.0 - ratio
    gap = max(L, 10)
    tolerance = max(3, (gap + 5) // 10)
    agreeing = 0
    for q in range(nq):
        partner = None
        for p in range(q - gap, -1, -1):
            if windows(p, L, ahead)[1] < windows(q, L, ahead)[0]:
                partner = p
                break
        if partner is None:
            for p in range(q + gap, nq):
                if windows(p, L, ahead)[0] > windows(q, L, ahead)[1]:
                    partner = p
                    break
        if best[q] < 0 or partner is None or best[partner] < 0:
            continue
        agreeing += abs((best[q] - best[partner]) - (q - partner)) <= tolerance
    return agreeing / nq, margin / nq


class CriteriaTest(unittest.TestCase):
    def test_against_numpy_on_the_sample(self):
        images = [openable.read_image(p) for p in openable.list_images(str(SAMPLE / "summer"))
                  + openable.list_images(str(SAMPLE / "winter"))]
        rows = openable.describe_images(images, descriptor="HOG")
        for L in (1, 10, 40):
            m = openable.distance_matrix(rows, L, traversal_starts=[0, 300])
            f = openable.unsupervised_criteria(m, reference_frames=300, sequence_length=L)
            consistency, distinctiveness = brute_criteria(m[300:, :300], L)
            self.assertAlmostEqual(f["consistency"], consistency, places=12, msg=L)
            self.assertAlmostEqual(f["distinctiveness"], distinctiveness, places=5, msg=L)
            self.assertAlmostEqual(f["agreement"], (10 * consistency + distinctiveness) / 11,
                                   places=5)
            self.assertEqual(f["queries"], 300)
            self.assertEqual(f["gap"], max(L, 10))
            self.assertEqual(f["best"].shape, (300,))
            self.assertEqual(int(f["agrees"].sum()), f["agreeing"])

    def test_shuffled_rows_and_a_single_column_rank_low(self):
        rng = np.random.default_rng(1)
        q = np.arange(100)
        clean = np.minimum(1, np.abs(q[None, :] - q[:, None]) / 20).astype(np.float32)
        clean += rng.random(clean.shape, dtype=np.float32) * 0.02
        shuffled = clean[rng.permutation(100)]
        stuck = np.ones((100, 100), np.float32)
        stuck[:, 42] = 0.01
        f = {name: openable.unsupervised_criteria(m, layout="query_reference")
             for name, m in (("clean", clean), ("shuffled", shuffled), ("stuck", stuck))}
        self.assertEqual(f["clean"]["consistency"], 1.0)
        self.assertLess(f["shuffled"]["consistency"], 0.1)
        self.assertEqual(f["stuck"]["consistency"], 0.0)
        self.assertGreater(f["stuck"]["distinctiveness"], f["clean"]["distinctiveness"])
        self.assertGreater(f["clean"]["agreement"], f["stuck"]["agreement"])
        self.assertGreater(f["clean"]["agreement"], f["shuffled"]["agreement"])
        with self.assertRaisesRegex(ValueError, "partial"):
            openable.unsupervised_criteria(clean, partial="later")


class AcceptConsistencyTest(unittest.TestCase):
    def test_hand_worked_example(self):
        # Query q's place is reference q + 100; query 15 answers 900 (wrong, 0.2), query 25 is
        # right but at 0.95. L = 1: partners 10 queries apart. The score alone accepts 29 (15
        # among them); one partner also refuses 15 and 5 (whose partner is 15).
        m = np.ones((30, 1000), np.float32)
        q = np.arange(30)
        m[q, q + 100] = 0.5
        m[15, 900] = 0.2
        m[25, 125] = 0.95
        pairs = np.stack([q, q + 100], axis=1)
        common = dict(pairs=pairs, layout="query_reference", normalize=False,
                      accept_threshold=0.9, partial="scale")
        alone = openable.evaluate(m, **common)
        confirmed = openable.evaluate(m, accept_consistency=1, **common)
        self.assertAlmostEqual(alone.operating_point["precision"], 28 / 29)
        self.assertEqual(confirmed.operating_point["precision"], 1.0)
        self.assertAlmostEqual(confirmed.operating_point["recall"], 27 / 30)
        self.assertEqual(confirmed.auc, alone.auc)


class SweepWithoutTruthTest(TempDirTestCase):
    def test_ranked_by_agreement_as_the_program(self):
        settings = {"Images_path": str(SAMPLE / "summer"), "Images_path_2": str(SAMPLE / "winter"),
                    "Npy_name": "", "Png_name": "", "Auto": False}
        config = SOURCE_DIR / "config" / "presets" / "auto.txt"
        result = openable.sweep(config, settings=settings, rank_by="agreement",
                                vary={"Image_descriptor": ["HOG", "LDB"],
                                      "Image_sequences": [10, 40]},
                                output=self.tmp / "py")
        self.assertEqual(result.rank_by, "agreement")
        agreement = [r["agreement"] for r in result.runs]
        self.assertEqual(agreement, sorted(agreement, reverse=True))
        self.assertIsNone(result.runs[0]["auc"])  # no ground truth
        self.assertEqual(len(result.written), 2)  # no precision-recall figure
        args = [config, "--quiet", "--rank-by", "agreement", "--vary", "Image_descriptor=HOG,LDB",
                "--vary", "Image_sequences=10,40", "--output", "cli"]
        for k, v in settings.items():
            args += ["--set", "%s=%s" % (k, int(v) if isinstance(v, bool) else v)]
        run("openable_sweep", args, self.tmp)
        cli = read_json(self.tmp / "cli.json")
        py = read_json(self.tmp / "py.json")
        self.assertEqual([r["settings"] for r in cli["runs"]], [r["settings"] for r in py["runs"]])
        self.assertEqual([r["unsupervised"] for r in cli["runs"]],
                         [r["unsupervised"] for r in py["runs"]])


if __name__ == "__main__":
    unittest.main()
