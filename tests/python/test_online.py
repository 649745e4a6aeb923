"""The online detector against the batch matrix, on KITTI 00 frames."""
import unittest

import numpy as np

import openable
from support import KITTI00, require

L, EXCLUSION, K, THRESHOLD = 3, 50, 5, 0.2


class OnlineAgainstBatchTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        require(KITTI00)
        paths = openable.list_images(str(KITTI00 / "image_0"))
        # Frames 0-299 and 1500-1699 (1559-1641 revisit 108-180), one sequence of 500.
        cls.paths = paths[:300] + paths[1500:1700]
        cls.images = [openable.read_image(p) for p in cls.paths[:80]]
        rows = [openable.describe_images(cls.images)]
        for i in range(80, len(cls.paths), 140):
            rows.append(openable.describe_images(
                [openable.read_image(p) for p in cls.paths[i:i + 140]]))
        cls.rows = np.vstack(rows)
        # The batch matrix M' and its divisor: M' x max = S, the raw sequence distances; with
        # partial="scale", the rule of the detector, which has not seen the frames after a
        # query yet.
        cls.matrix, cls.peak = openable.distance_matrix(cls.rows, L, return_max=True,
                                                        partial="scale")
        cls.sums = openable.sequence_distances(openable.hamming_distances(cls.rows), L,
                                               partial="scale")
        cls.sums = cls.sums.astype(np.float64)
        # consistency=0: the score alone decides (test_map_tuning checks the confirmation).
        cls.detector = openable.OnlineDetector(sequence_length=L, exclusion=EXCLUSION,
                                               candidates=K, threshold=THRESHOLD, consistency=0)
        cls.results = [cls.detector.add_descriptor(row) for row in cls.rows]

    def expected(self, q):
        """The K best earlier frames j <= q - EXCLUSION of the batch sums (ties: earlier)."""
        eligible = np.arange(0, q - EXCLUSION + 1)
        order = sorted(eligible, key=lambda j: (round(self.sums[q, j], 2), j))
        return order[:K]

    def test_candidates_are_the_best_of_the_batch_matrix(self):
        accepted = 0
        for q, (frame, candidates, timings) in enumerate(self.results):
            self.assertEqual(frame, q)
            self.assertIn("search_seconds", timings)
            if q < EXCLUSION:
                self.assertEqual(candidates, [])
                continue
            self.assertEqual(len(candidates), min(K, q - EXCLUSION + 1))
            self.assertEqual([c[0] for c in candidates], self.expected(q), "frame %d" % q)
            for j, distance, normalized, ok, score in candidates:
                self.assertAlmostEqual(distance, self.sums[q, j], delta=1e-3 * max(1, distance))
                self.assertAlmostEqual(normalized, distance / (L * 256), places=9)
                self.assertEqual(score, normalized)  # the distance score
                self.assertEqual(ok, normalized <= THRESHOLD)
                accepted += ok
        self.assertGreater(accepted, 0)

    def test_ratio_score_against_brute_force(self):
        # While the search is exact every earlier frame j <= q - EXCLUSION is a rival: the
        # ratio of candidate j is S(q, j) over the smallest S(q, j') with |j' - j| > W.
        W, ratio_threshold = 10, 0.9
        d = openable.OnlineDetector(sequence_length=L, exclusion=EXCLUSION, candidates=K,
                                    score="ratio", score_window=W, threshold=ratio_threshold,
                                    consistency=0)
        self.assertEqual(d.options["score"], "ratio")
        checked = 0
        for q, row in enumerate(self.rows):
            _, candidates, _ = d.add_descriptor(row)
            eligible = np.arange(0, q - EXCLUSION + 1)
            for j, distance, _, ok, score in candidates:
                rivals = self.sums[q, eligible[np.abs(eligible - j) > W]]
                expected = 1.0 if rivals.size == 0 or rivals.min() <= 0 else \
                    self.sums[q, j] / rivals.min()
                self.assertAlmostEqual(score, expected, delta=1e-4, msg="frame %d, %d" % (q, j))
                self.assertEqual(ok, score <= ratio_threshold)
                checked += 1
        self.assertGreater(checked, 1000)
        with self.assertRaises(ValueError):
            openable.OnlineDetector(score="confidence")
        with self.assertRaisesRegex(openable.InputError, "score_window"):
            openable.OnlineDetector(score_window=-1)
        with self.assertRaisesRegex(openable.InputError, "stereo"):
            openable.OnlineDetector(descriptor="D-LDB")

    def test_batch_matrix_is_the_sums_over_their_maximum(self):
        np.testing.assert_allclose(self.matrix * self.peak, self.sums, rtol=1e-6, atol=1e-3)
        self.assertEqual(self.peak, self.sums.max())

    def test_revisit_is_found(self):
        # Frame 1600 of KITTI (row 400 here) revisits about frame 150.
        _, candidates, _ = self.results[400]
        self.assertTrue(candidates[0][3], candidates)
        self.assertLess(abs(candidates[0][0] - 150), 30, candidates)

    def test_state(self):
        d = self.detector
        self.assertEqual(d.size, len(self.rows))
        self.assertEqual(len(d), len(self.rows))
        self.assertEqual(d.row_width, 32)
        self.assertEqual(d.row_dtype, np.uint8)
        self.assertEqual(d.blocks, 0)
        self.assertGreaterEqual(d.memory_bytes, self.rows.nbytes)
        rows = d.descriptors
        np.testing.assert_array_equal(rows, self.rows)
        self.assertFalse(rows.flags.writeable)
        self.assertEqual(d.options["sequence_length"], L)

    def test_frames_give_the_rows_of_describe(self):
        d = openable.OnlineDetector(sequence_length=L, exclusion=EXCLUSION, candidates=K,
                                    threshold=THRESHOLD)
        for q, image in enumerate(self.images):
            frame, candidates, timings = d.add_frame(image)
            self.assertEqual(candidates, self.results[q][1])
            self.assertGreaterEqual(timings["describe_seconds"], 0)
        np.testing.assert_array_equal(d.descriptors, self.rows[:len(self.images)])
        # A stack of images is a list of images.
        np.testing.assert_array_equal(openable.describe_images(np.stack(self.images[:6])),
                                      self.rows[:6])
        # uint8 images give the same rows as float32 ones.
        as_bytes = np.round(self.images[3] * 255).astype(np.uint8)
        np.testing.assert_array_equal(openable.describe(as_bytes), self.rows[3])

    def test_approximate_search_distances_are_exact(self):
        d = openable.OnlineDetector(sequence_length=L, exclusion=EXCLUSION, candidates=K,
                                    threshold=THRESHOLD, exact_limit=100, block_frames=64,
                                    background_merges=False)
        used = False
        for q, row in enumerate(self.rows):
            _, candidates, timings = d.add_descriptor(row)
            used = used or timings["approximate"]
            for j, distance, _, _, _ in candidates:
                self.assertLessEqual(j, q - EXCLUSION)
                self.assertAlmostEqual(distance, self.sums[q, j], delta=1e-3 * max(1, distance))
        self.assertTrue(used)
        d.finish_merges()
        self.assertGreater(d.blocks, 0)
        self.assertFalse(d.options["background_merges"])

    def test_saved_map_gives_the_same_candidates(self):
        import os
        import pathlib
        import tempfile
        options = dict(sequence_length=L, exclusion=EXCLUSION, candidates=K, threshold=THRESHOLD,
                       exact_limit=100, block_frames=64, background_merges=False)
        yesterday = openable.OnlineDetector(**options)
        for row in self.rows[:300]:
            yesterday.add_descriptor(row)
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "kitti.map")
            yesterday.save_map(path)
            today = openable.OnlineDetector(**options)
            info = today.load_map(pathlib.Path(path))  # os.PathLike as well as str
            self.assertEqual(info["frames"], 300)
            self.assertFalse(info["rebuilt"])
            self.assertEqual(info["blocks"], yesterday.blocks)
            self.assertGreater(today.blocks, 0)
            np.testing.assert_array_equal(today.descriptors, yesterday.descriptors)
            for row in self.rows[300:]:
                self.assertEqual(today.add_descriptor(row)[1], yesterday.add_descriptor(row)[1])
            # A damaged file: one line naming it; checked before loading, the detector stays
            # empty; checked in the background (the default), check_map() reports it.
            data = bytearray(open(path, "rb").read())
            data[len(data) // 2] ^= 1
            with open(path, "wb") as f:
                f.write(data)
            fresh = openable.OnlineDetector(**options)
            with self.assertRaisesRegex(openable.InputError, "kitti.map: the map is damaged"):
                fresh.load_map(path, check_in_background=False)
            self.assertEqual(fresh.size, 0)
            fresh.load_map(path)
            with self.assertRaisesRegex(openable.InputError, "kitti.map: the map is damaged"):
                fresh.check_map()

    def test_threads_share_a_detector(self):
        # add_descriptor releases the GIL; the detector's lock keeps frames whole.
        import threading
        d = openable.OnlineDetector(sequence_length=L, exclusion=EXCLUSION)
        frames = []

        def feed(rows):
            for row in rows:
                frames.append(d.add_descriptor(row)[0])

        threads = [threading.Thread(target=feed, args=(self.rows[k::2],)) for k in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        self.assertEqual(sorted(frames), list(range(len(self.rows))))
        self.assertEqual(d.size, len(self.rows))
        self.assertEqual(sorted(map(bytes, d.descriptors)), sorted(map(bytes, self.rows)))

    def test_bad_options_and_rows(self):
        with self.assertRaises(ValueError):
            openable.OnlineDetector(exclusion=0)
        with self.assertRaises(ValueError):
            openable.OnlineDetector(description="mosaic")
        d = openable.OnlineDetector()
        with self.assertRaises(ValueError):
            d.add_descriptor(np.zeros(16, np.uint8))
        with self.assertRaises(ValueError):
            d.add_frame(np.zeros((2, 2, 2), np.uint8))


if __name__ == "__main__":
    unittest.main()
