"""Python against Test_OpenABLE on real data: the same matrix (.npy) and the same evaluation
(JSON, CSV curves), plus checks against values computed here with NumPy alone."""
import csv
import math
import unittest

import numpy as np

import openable
from support import KITTI00, NORDLAND, TempDirTestCase, kitti_poses, read_json, require, run


def describe_folder(folder, first=0, last=None, batch=200, **options):
    """Rows of the images [first, last) of a folder, described in batches (bounded memory)."""
    paths = openable.list_images(str(folder))[first:last]
    rows = []
    for i in range(0, len(paths), batch):
        rows.append(openable.describe_images([openable.read_image(p) for p in paths[i:i + batch]],
                                             **options))
    return np.vstack(rows)


def read_curve(path):
    with open(path) as f:
        table = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in table]) for k in table[0]}


def close(a, b):
    return math.isclose(a, b, rel_tol=1e-7, abs_tol=1e-9)  # the files hold 9 digits


class ParityMixin:
    """Compares an EvaluationResult with the files Test_OpenABLE wrote under prefix `eval`."""

    def check_evaluation(self, result, prefix="eval"):
        report = read_json(self.tmp / (prefix + ".json"))["runs"][0]
        per_query, able_p = report["per_query"], report["able_p"]
        for key in ("auc", "recall_at_100p", "max_f1", "max_f1_threshold", "max_f1_precision",
                    "max_f1_recall", "recall_at_1", "recall_at_5", "recall_at_10"):
            self.assertTrue(close(getattr(result, key), per_query[key]),
                            "%s: %r (Python) vs %r (Test_OpenABLE)" % (key, getattr(result, key),
                                                                        per_query[key]))
        for key in ("queries", "positive_queries", "truth_pairs_outside_candidates"):
            self.assertEqual(getattr(result, key), per_query[key], key)
        self.assertEqual(result.truth_pairs, report["ground_truth"]["pairs"])
        self.assertTrue(close(result.average_precision, able_p["average_precision_percent"]))
        self.assertEqual(result.candidate_cells, able_p["candidate_cells"])
        self.assertEqual(result.truth_cells, able_p["truth_cells"])
        for curve, name in ((result.curve, "_per_query.csv"), (result.able_p_curve, "_ablep.csv")):
            expected = read_curve(self.tmp / (prefix + name))
            self.assertEqual(len(curve), len(expected["threshold"]))
            for column in ("threshold", "precision", "recall", "f1", "tp", "fp"):
                np.testing.assert_allclose(getattr(curve, column), expected[column],
                                           rtol=1e-7, atol=1e-9, err_msg=column)
        self.assertTrue(close(result.curve.area(), result.auc))


class Kitti00LoopClosureTest(ParityMixin, TempDirTestCase):
    """KITTI 00 frames 0-1699 (the loop at frames 1559-1641 revisits 108-180): LDB, L = 5,
    loops from the poses (5 m in the ground plane, headings within 45 degrees, 120 frames
    apart), tolerance 3, vicinity 5."""

    L = 5

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        require(KITTI00)
        cls.poses_file = KITTI00 / "poses" / "00_first1700.txt"
        run("Test_OpenABLE",
            ["--quiet", "--set", "Images_path=%s" % (KITTI00 / "image_0"), "--set",
             "Images_path_2=", "--set", "Image_sequences=%d" % cls.L, "--set", "Txt_name=",
             "--set", "Png_name=", "--set", "Threshold=-1", "--set", "Npy_name=m.npy",
             "--set", "Ground_truth_type=kitti", "--set", "Ground_truth=%s" % cls.poses_file,
             "--set", "Ground_truth_axes=xz", "--set", "Ground_truth_radius=5", "--set",
             "Ground_truth_heading=45", "--set", "Exclusion=120", "--set", "Tolerance=3",
             "--set", "Vicinity=5", "--set", "Evaluation_name=eval"], cls.tmp)
        cls.cli = np.load(cls.tmp / "m.npy")
        cls.rows = describe_folder(KITTI00 / "image_0")
        cls.matrix, cls.peak = openable.distance_matrix(cls.rows, cls.L, return_max=True)
        cls.poses = kitti_poses(cls.poses_file)

    def test_rows_are_ldb_of_the_frames(self):
        self.assertEqual(self.rows.shape, (1700, 32))
        self.assertEqual(self.rows.dtype, np.uint8)
        one = openable.describe(openable.read_image(openable.list_images(str(KITTI00 / "image_0"))[7]))
        np.testing.assert_array_equal(one, self.rows[7])

    def test_matrix_equals_the_programs(self):
        self.assertEqual(self.matrix.shape, self.cli.shape)
        # Cells without a value (Sequence_partial ahead: diagonals shorter than L) are +inf in
        # memory and NaN in the .npy file.
        np.testing.assert_allclose(self.matrix, self.cli, rtol=1e-6,
                                   atol=1e-7)
        self.assertEqual(type(self.matrix.base).__name__, "PyCapsule")

    def test_matrix_from_brute_force_hamming(self):
        # Single-frame distances of 60 rows against all, bit by bit with NumPy; then the
        # matrix is their sequence sums over the maximum.
        sample = np.arange(0, 1700, 29)
        bits = np.stack([np.unpackbits(self.rows[i] ^ self.rows, axis=1).sum(axis=1)
                         for i in sample])
        d = openable.hamming_distances(self.rows)
        np.testing.assert_array_equal(d[sample], bits)
        s = openable.sequence_distances(d, self.L)
        np.testing.assert_allclose(self.matrix * self.peak, s, rtol=1e-5, atol=1e-3)
        self.assertAlmostEqual(self.peak, float(s[np.isfinite(s)].max()), places=2)

    def test_evaluation_equals_the_programs(self):
        protocol = dict(exclusion=120, tolerance=3, vicinity=5)  # not the defaults
        r = openable.evaluate(self.cli, poses=self.poses, radius=5, axes="xz", heading_limit=45,
                              **protocol)
        self.assertEqual(r.layout, "loop_closure")
        self.assertGreater(r.positive_queries, 50)  # the loop is there
        self.check_evaluation(r)
        # The same ground truth read from the file, as the program read it.
        from_file = openable.evaluate(self.matrix, truth_file=str(self.poses_file),
                                      truth_type="kitti", radius=5, axes="xz", heading_limit=45,
                                      **protocol)
        self.check_evaluation(from_file)
        np.testing.assert_array_equal(from_file.truth_matches(), r.truth_matches())
        # The same pairs given as pairs (either order: loop closure takes the later frame as
        # the query), and as a symmetric 0/1 matrix.
        pairs = r.truth_matches()
        self.check_evaluation(openable.evaluate(self.cli, pairs=pairs[:, ::-1], **protocol))
        truth = np.zeros(self.cli.shape, np.uint8)
        truth[pairs[:, 0], pairs[:, 1]] = truth[pairs[:, 1], pairs[:, 0]] = 1
        self.check_evaluation(openable.evaluate(self.cli, truth_matrix=truth, **protocol))

    def test_positions_without_headings(self):
        positions = openable.evaluate(self.cli, poses=self.poses[:, :, 3], radius=5, axes="xz")
        kitti = openable.evaluate(self.cli, truth_file=str(self.poses_file), truth_type="kitti",
                                  radius=5, axes="xz")
        self.assertEqual(positions.to_dict().keys(), kitti.to_dict().keys())
        for key, value in kitti.to_dict().items():
            if not isinstance(value, dict):
                self.assertEqual(getattr(positions, key), value, key)
        with_headings = openable.evaluate(self.cli, poses=self.poses, radius=5, axes="xz",
                                          heading_limit=45)
        self.assertGreater(kitti.truth_pairs, with_headings.truth_pairs)
        with self.assertRaisesRegex(ValueError, "heading_limit"):
            openable.evaluate(self.cli, poses=self.poses[:, :, 3], heading_limit=45)

    def test_recall_at_1_from_numpy(self):
        # Ground truth and R@1 written out with NumPy: loops are frames 100 apart or more,
        # within 5 m in the x-z plane, optical axes (x-z) within 45 degrees.
        xz = self.poses[:, [0, 2], 3]
        axis = self.poses[:, [0, 2], 2]
        axis = axis / np.linalg.norm(axis, axis=1, keepdims=True)
        n, positive, correct = len(xz), 0, 0
        for q in range(100, n):
            j = np.arange(q - 100 + 1)
            near = np.linalg.norm(xz[j] - xz[q], axis=1) < 5
            heading = np.degrees(np.arccos(np.clip(axis[j] @ axis[q], -1, 1))) < 45
            truth = j[near & heading]
            if len(truth) == 0:
                continue
            positive += 1
            best = int(np.nanargmin(self.cli[q, :q - 100 + 1]))
            correct += int(np.min(np.abs(truth - best)) <= 2)
        r = openable.evaluate(self.matrix, poses=self.poses, radius=5, axes="xz",
                              heading_limit=45)
        self.assertEqual(r.positive_queries, positive)
        self.assertAlmostEqual(r.recall_at_1, correct / positive, places=12)
        self.assertEqual(int(r.correct[r.positive].sum()), correct)


class NordlandTwoTraversalsTest(ParityMixin, TempDirTestCase):
    """Nordland, 500 summer (reference) and 500 winter (query) frames, frame-aligned;
    tolerance 1, vicinity 3."""

    FRAMES = 500

    def run_both(self, descriptor, description, extra_sets, **options):
        sets = ["--quiet", "--set", "Images_path=%s" % (NORDLAND / "summer"), "--set",
                "Images_path_2=%s" % (NORDLAND / "winter"), "--set",
                "Final_image=%d" % self.FRAMES, "--set", "Image_descriptor=%s" % descriptor,
                "--set", "Description_type=%d" % (description == "grid"), "--set",
                "Image_sequences=10", "--set", "Txt_name=", "--set", "Png_name=", "--set",
                "Threshold=-1", "--set", "Npy_name=m.npy", "--set", "Ground_truth_type=aligned",
                "--set", "Tolerance=1", "--set", "Vicinity=3", "--set", "Evaluation_name=eval"] + extra_sets
        run("Test_OpenABLE", sets, self.tmp)
        cli = np.load(self.tmp / "m.npy")
        rows = np.vstack([describe_folder(NORDLAND / season, 0, self.FRAMES,
                                          descriptor=descriptor, description=description,
                                          **options)
                          for season in ("summer", "winter")])
        matrix = openable.distance_matrix(rows, 10, traversal_starts=[0, self.FRAMES])
        np.testing.assert_allclose(matrix, cli, rtol=1e-5, atol=1e-6)
        r = openable.evaluate(matrix, aligned=True, reference_frames=self.FRAMES, tolerance=1,
                              vicinity=3)
        self.assertEqual(r.layout, "query_reference")
        self.assertEqual(r.block, (self.FRAMES, 0, self.FRAMES, self.FRAMES))
        self.check_evaluation(r)
        # The block alone, as a queries x references matrix, with the ground truth as a matrix.
        block = np.ascontiguousarray(cli[self.FRAMES:, :self.FRAMES])
        r2 = openable.evaluate(block, truth_matrix=np.eye(self.FRAMES, dtype=bool),
                               layout="query_reference", tolerance=1, vicinity=3)
        self.check_evaluation(r2)
        return rows, r

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        require(NORDLAND)

    def test_ldb_global(self):
        rows, r = self.run_both("LDB", "global", [])
        self.assertEqual(rows.dtype, np.uint8)
        self.assertGreater(r.recall_at_1, 0.05)

    def test_hog_grid(self):
        rows, _ = self.run_both("HOG", "grid", ["--set", "Grid_x=2", "--set", "Grid_y=1",
                                                "--set", "Patch_size=32"],
                                grid=(2, 1), patch_size=32)
        self.assertEqual(rows.dtype, np.float32)


if __name__ == "__main__":
    unittest.main()
