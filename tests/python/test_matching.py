"""Distance matrices from Python against values computed here with NumPy alone."""
import unittest

import numpy as np

import openable


def hamming_reference(a, b):
    """Bits differing between every row of a and every row of b (NumPy only)."""
    out = np.empty((len(a), len(b)), dtype=np.int64)
    for i in range(len(a)):
        out[i] = np.unpackbits(a[i][None, :] ^ b, axis=1).sum(axis=1)
    return out


def sequence_reference(d, length, direction, row_starts=(0,), col_starts=(0,), skip=False,
                       ahead=False):
    """S of matching/sequence.h written out term by term in float64 (skip: +inf where fewer
    than L terms exist; ahead: such a cell sums the first L cells of its diagonal, +inf when
    the diagonal holds fewer than L cells)."""
    n, m = d.shape
    row_starts, col_starts = list(row_starts), list(col_starts)
    row_bounds = [(s, e) for s, e in zip(row_starts, row_starts[1:] + [n])]
    col_bounds = [(s, e) for s, e in zip(col_starts, col_starts[1:] + [m])]

    def bounds(bounds_list, x):
        return next(b for b in bounds_list if b[0] <= x < b[1])

    def one(step):
        s = np.zeros((n, m))
        for i in range(n):
            r0, r1 = bounds(row_bounds, i)
            for j in range(m):
                c0, c1 = bounds(col_bounds, j)
                if ahead:
                    # The cells of the diagonal through (i, j) inside both traversals, in order.
                    a, b = i, j
                    while a - 1 >= r0 and c0 <= b + step < c1:
                        a, b = a - 1, b + step
                    cells = []
                    while a < r1 and c0 <= b < c1:
                        cells.append((a, b))
                        a, b = a + 1, b - step
                    p = i - cells[0][0]
                    if len(cells) < length:
                        s[i, j] = np.inf
                        continue
                    first = p - length + 1 if p >= length - 1 else 0
                    s[i, j] = sum(d[x, y] for x, y in cells[first:first + length])
                    continue
                total, count = 0.0, 0
                for k in range(length):
                    ii, jj = i - k, j + step * k
                    if ii < r0 or jj < c0 or jj >= c1:
                        break
                    total += d[ii, jj]
                    count += 1
                s[i, j] = np.inf if skip and count < length else total * length / count
        return s

    if direction == "forward":
        return one(-1)
    if direction == "reverse":
        return one(+1)
    return np.minimum(one(-1), one(+1))


class HammingTest(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(7)
        self.a = rng.integers(0, 256, (37, 32), dtype=np.uint8)
        self.b = rng.integers(0, 256, (23, 32), dtype=np.uint8)

    def test_against_unpackbits(self):
        np.testing.assert_array_equal(openable.hamming_distances(self.a, self.b),
                                      hamming_reference(self.a, self.b))
        square = openable.hamming_distances(self.a)
        np.testing.assert_array_equal(square, hamming_reference(self.a, self.a))
        self.assertEqual(square.shape, (37, 37))
        np.testing.assert_array_equal(np.diag(square), 0)

    def test_result_is_the_cpp_buffer(self):
        d = openable.hamming_distances(self.a, self.b)
        self.assertEqual(d.dtype, np.float32)
        self.assertFalse(d.flags.owndata)  # memory held by the capsule of the cv::Mat
        self.assertEqual(type(d.base).__name__, "PyCapsule")
        self.assertTrue(d.flags.c_contiguous and d.flags.writeable)

    def test_strided_and_converted_inputs(self):
        # Rows at a stride (a view of every other row, the first 16 bytes of each row), a
        # Fortran-ordered copy, one 1-D row: each gives the brute-force values.
        for a in (self.a[::2], self.a[:, :16], np.asfortranarray(self.a), self.a[5]):
            a_np = np.atleast_2d(np.asarray(a, dtype=np.uint8))
            np.testing.assert_array_equal(openable.hamming_distances(a, a_np),
                                          hamming_reference(a_np, a_np))

    def test_refuses_other_types_and_widths(self):
        with self.assertRaisesRegex(ValueError, "uint8"):
            openable.hamming_distances(self.a.astype(np.float32))
        with self.assertRaisesRegex(ValueError, "16 elements; expected 32"):
            openable.hamming_distances(self.a, self.b[:, :16])
        with self.assertRaisesRegex(ValueError, "2-D"):
            openable.hamming_distances(np.zeros((2, 2, 2), np.uint8))


class L2Test(unittest.TestCase):
    def test_against_numpy(self):
        rng = np.random.default_rng(3)
        a = rng.random((40, 128), dtype=np.float32)
        b = rng.random((31, 128), dtype=np.float32)
        ref = np.sqrt(((a[:, None, :].astype(np.float64) - b[None, :, :]) ** 2).sum(axis=2))
        np.testing.assert_allclose(openable.l2_distances(a, b), ref, rtol=1e-5, atol=1e-5)
        # float64 input is converted to float32.
        np.testing.assert_allclose(openable.l2_distances(a.astype(np.float64), b), ref,
                                   rtol=1e-5, atol=1e-5)
        square = openable.l2_distances(a)
        np.testing.assert_allclose(np.diag(square), 0, atol=1e-6)


class SequenceTest(unittest.TestCase):
    def test_against_the_sums_written_out(self):
        rng = np.random.default_rng(11)
        d = rng.random((30, 26), dtype=np.float32) * 100
        cases = [
            (1, "forward", None, None),
            (4, "forward", None, None),
            (4, "reverse", None, None),
            (3, "both", None, None),
            (5, "forward", [0, 12], [0, 10]),
            (5, "reverse", [0, 12], [0, 10]),
        ]
        for length, direction, rows, cols in cases:
            for partial in ("ahead", "scale"):  # the default first
                with self.subTest(L=length, direction=direction, starts=rows, partial=partial):
                    got = (openable.sequence_distances(d, length, direction, rows, cols)
                           if partial == "ahead" else
                           openable.sequence_distances(d, length, direction, rows, cols,
                                                       partial=partial))
                    ref = sequence_reference(d.astype(np.float64), length, direction,
                                             rows or [0], cols or [0], ahead=partial == "ahead")
                    np.testing.assert_allclose(got, ref, rtol=2e-6, atol=1e-4)

    def test_in_place_writes_into_the_given_array(self):
        rng = np.random.default_rng(5)
        d = rng.random((20, 20), dtype=np.float32)
        expected = openable.sequence_distances(d, 3)
        out = openable.sequence_distances(d, 3, in_place=True)
        self.assertTrue(np.shares_memory(out, d))
        np.testing.assert_array_equal(d, expected)
        with self.assertRaisesRegex(ValueError, "in_place"):
            openable.sequence_distances(d.astype(np.float64), 3, in_place=True)

    def test_bad_arguments(self):
        d = np.ones((4, 4), np.float32)
        with self.assertRaisesRegex(ValueError, "sequence length"):
            openable.sequence_distances(d, 0)
        with self.assertRaisesRegex(ValueError, "direction"):
            openable.sequence_distances(d, 2, "sideways")
        with self.assertRaises(ValueError):
            openable.sequence_distances(d, 2, row_starts=[1, 2])


class NormalizeThresholdTest(unittest.TestCase):
    def test_eq5_and_eq9(self):
        rng = np.random.default_rng(2)
        m = rng.random((9, 7), dtype=np.float32) * 40
        normalized, peak = openable.normalize_by_max(m)
        self.assertAlmostEqual(peak, float(m.max()), places=4)
        np.testing.assert_allclose(normalized, m / m.max(), rtol=1e-6)
        np.testing.assert_array_equal(openable.threshold_matrix(normalized, 0.3),
                                      (normalized >= 0.3).astype(np.uint8))
        with self.assertRaisesRegex(ValueError, "negative or NaN"):
            openable.normalize_by_max(-m)
        # +inf (a skipped sequence cell) is left out of the maximum and stays +inf.
        with_inf = m.copy()
        with_inf[0, 0] = np.inf
        normalized, peak = openable.normalize_by_max(with_inf)
        self.assertAlmostEqual(peak, float(m[np.isfinite(with_inf)].max()), places=4)
        self.assertEqual(normalized[0, 0], np.inf)

    def test_read_matrix_reads_numpy_files(self):
        import tempfile, os
        m = np.arange(12, dtype=np.float64).reshape(3, 4) / 11
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "m.npy")
            np.save(path, m)
            np.testing.assert_allclose(openable.read_matrix(path), m, rtol=1e-7)
            with self.assertRaises(openable.InputError):
                openable.read_matrix(os.path.join(tmp, "missing.npy"))


class SeqSlamPiecesTest(unittest.TestCase):
    def test_skip_partial_sequences(self):
        rng = np.random.default_rng(13)
        d = rng.random((24, 20), dtype=np.float32) * 100
        for direction in ("forward", "reverse", "both"):
            got = openable.sequence_distances(d, 4, direction, [0, 10], [0, 8], partial="skip")
            ref = sequence_reference(d.astype(np.float64), 4, direction, [0, 10], [0, 8],
                                     skip=True)
            np.testing.assert_array_equal(np.isinf(got), np.isinf(ref))
            finite = np.isfinite(ref)
            np.testing.assert_allclose(got[finite], ref[finite], rtol=2e-6, atol=1e-4)
        with self.assertRaisesRegex(ValueError, "partial"):
            openable.sequence_distances(d, 4, partial="drop")

    def test_l1_distances_and_sad_rows(self):
        rng = np.random.default_rng(3)
        a = rng.integers(0, 256, (7, 70), dtype=np.uint8)
        b = rng.integers(0, 256, (5, 70), dtype=np.uint8)
        ref = np.abs(a[:, None, :].astype(np.int64) - b[None, :, :]).sum(axis=2)
        np.testing.assert_array_equal(openable.l1_distances(a, b), ref)
        images = [rng.integers(0, 256, (60, 120), dtype=np.uint8) for _ in range(4)]
        rows = openable.describe_images(images, descriptor="SAD")
        self.assertEqual(rows.shape, (4, 64 * 32))
        self.assertEqual(rows.dtype, np.uint8)
        m = openable.distance_matrix(rows, metric="l1")
        l1 = openable.l1_distances(rows).astype(np.float64)
        np.testing.assert_allclose(m, l1 / l1.max(), rtol=1e-6)
        with self.assertRaises(openable.InputError):
            openable.distance_matrix(rows, metric="l2")  # l2 needs float32 rows

    def test_contrast_enhancement_written_out(self):
        rng = np.random.default_rng(8)
        d = rng.random((6, 30), dtype=np.float32) * 50
        w = 4
        ref = np.zeros(d.shape)
        for i in range(d.shape[0]):
            for j in range(d.shape[1]):
                win = d[i, max(0, j - w):j + w + 1].astype(np.float64)
                ref[i, j] = (d[i, j] - win.mean()) / win.std()
        ref -= ref.min()
        np.testing.assert_allclose(openable.contrast_enhancement(d, w), ref, atol=1e-4)

    def test_best_matches_and_the_ratio(self):
        m = np.array([[0.5, 0.9, 0.25, 0.2, 0.3, 0.8],
                      [np.inf, np.inf, np.inf, np.inf, np.inf, np.inf]], dtype=np.float32)
        best, distance, score = openable.best_matches(m, "ratio", 1)
        self.assertEqual(list(best), [3, -1])
        self.assertAlmostEqual(float(distance[0]), 0.2, places=6)
        self.assertAlmostEqual(float(score[0]), 0.2 / 0.5, places=6)
        self.assertTrue(np.isnan(score[1]))
        _, _, score = openable.best_matches(m, "distance")
        self.assertAlmostEqual(float(score[0]), 0.2, places=6)

    def test_evaluate_with_the_ratio_score(self):
        # Two queries: q0's wrong best match has a close rival, q1's right one stands out.
        m = np.array([[0.10, 0.9, 0.9, 0.11, 0.5],
                      [0.9, 0.9, 0.9, 0.9, 0.30]], dtype=np.float32)
        pairs = [(0, 4), (1, 4)]
        by_distance = openable.evaluate(m, pairs=pairs, tolerance=0, normalize=False)
        self.assertEqual(by_distance.recall_at_100p, 0.0)
        by_ratio = openable.evaluate(m, pairs=pairs, tolerance=0, normalize=False,
                                     score="ratio", score_window=1, accept_threshold=0.5)
        self.assertEqual(by_ratio.score, "ratio")
        self.assertAlmostEqual(by_ratio.recall_at_100p, 0.5)
        np.testing.assert_allclose(by_ratio.scores, [0.10 / 0.11, 0.30 / 0.9], rtol=1e-6)
        self.assertEqual(by_ratio.operating_point["precision"], 1.0)
        self.assertAlmostEqual(by_ratio.operating_point["recall"], 0.5)
        with self.assertRaisesRegex(openable.InputError, "score_window"):
            openable.evaluate(m, pairs=pairs, score="ratio", score_window=5)


if __name__ == "__main__":
    unittest.main()
