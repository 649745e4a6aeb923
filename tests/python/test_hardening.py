"""Inputs outside their domain get the programs' checks and one-line errors, never a silently
wrong result or a crash: float images outside [0, 1], a conversion that cannot be allocated,
negative or NaN distances, thresholds outside [0, 1], traversal starts beyond the rows,
trajectories whose timestamps do not increase."""
import _thread
import os
import shutil
import tempfile
import threading
import time
import unittest

import numpy as np

import openable
from openable import snaps
from support import SAMPLE


class HardeningTest(unittest.TestCase):
    def test_float_images_outside_zero_one_are_refused(self):
        image = np.full((32, 64), 200.0, np.float32)  # a 0-255 image given as float
        with self.assertRaises(ValueError) as caught:
            openable.describe(image)
        self.assertIn("[0, 1]", str(caught.exception))
        self.assertIn("200", str(caught.exception))
        image[0, 0] = np.nan
        with self.assertRaises(ValueError):
            openable.describe(image / 255.0)
        # The same image scaled to [0, 1] is described as its uint8 version.
        grey = (np.arange(32 * 64) % 256).astype(np.uint8).reshape(32, 64)
        np.testing.assert_array_equal(openable.describe(grey / np.float32(255)),
                                      openable.describe(grey))

    def test_a_copy_that_cannot_be_allocated_raises_memory_error(self):
        # A broadcast view of 10^12 elements: converting it needs terabytes.
        huge = np.broadcast_to(np.zeros((1, 1), np.float64), (10**6, 10**6))
        with self.assertRaises(MemoryError):
            openable.sequence_distances(huge, 2)
        huge_image = np.broadcast_to(np.zeros((1, 1), np.float64), (10**6, 10**6))
        with self.assertRaises(MemoryError):
            openable.describe(huge_image)

    def test_evaluate_applies_the_checks_of_openable_evaluate(self):
        m = np.random.default_rng(1).random((20, 20)).astype(np.float32)
        bad = m.copy()
        bad[3, 7] = -1
        with self.assertRaises(openable.InputError) as caught:
            openable.evaluate(bad, aligned=True, reference_frames=10)
        self.assertIn("row 3, column 7", str(caught.exception))
        # +inf is a cell without a value, as in a saved .npy: a query with only +inf candidates
        # has no answer.
        skipped = m.copy()
        skipped[15, :10] = np.inf
        result = openable.evaluate(skipped, aligned=True, reference_frames=10)
        self.assertEqual(result.unanswered_queries, 1)
        # NaN is damage, refused with the cell, whatever band it lies in: never read as skipped.
        for row, col in ((15, 3), (0, 0), (19, 19)):
            nan = m.copy()
            nan[row, col] = np.nan
            with self.assertRaises(openable.InputError) as caught:
                openable.evaluate(nan, aligned=True, reference_frames=10)
            self.assertIn(f"NaN at row {row}, column {col}: a damaged matrix", str(caught.exception))
            with self.assertRaises(openable.InputError):
                openable.unsupervised_criteria(nan, reference_frames=10)
        with self.assertRaises(ValueError):
            openable.evaluate(np.zeros((0, 0), np.float32), aligned=True)

    def test_ctrl_c_stops_the_sequence_sums(self):
        # Ctrl-C (interrupt_main, 0.05 s into the call) during the sums of a 10000 x 10000
        # matrix, summed in place: KeyboardInterrupt must end them part-way (the last rows still
        # hold the single-frame distances), not once every row is summed.
        single = np.random.default_rng(3).random((10000, 10000), dtype=np.float32)
        work = single.copy()

        def press():
            time.sleep(0.05)
            _thread.interrupt_main()

        thread = threading.Thread(target=press)
        thread.start()
        with self.assertRaises(KeyboardInterrupt):
            openable.sequence_distances(work, 10, in_place=True)
        thread.join()
        np.testing.assert_array_equal(work[-10:], single[-10:])
        self.assertFalse(np.array_equal(work[:20], single[:20]))

    def test_threshold_matrix_domain(self):
        m = np.array([[0.1, 0.5], [0.9, 0.2]], np.float32)
        np.testing.assert_array_equal(openable.threshold_matrix(m, 0.3), [[0, 1], [1, 0]])
        for theta in (-0.1, 1.5, float("nan")):
            with self.assertRaises(ValueError):
                openable.threshold_matrix(m, theta)
        m[0, 1] = np.nan
        with self.assertRaises(ValueError) as caught:
            openable.threshold_matrix(m, 0.3)
        self.assertIn("row 0, column 1", str(caught.exception))

    def test_traversal_starts_beyond_the_rows(self):
        rows = np.random.default_rng(2).integers(0, 256, (6, 32), dtype=np.uint8)
        openable.distance_matrix(rows, traversal_starts=[0, 3])
        with self.assertRaises(ValueError) as caught:
            openable.distance_matrix(rows, traversal_starts=[0, 9])
        self.assertIn("9", str(caught.exception))

    def test_file_names_that_are_not_utf8(self):
        folder = tempfile.mkdtemp(prefix="openable_names_")
        try:
            source = sorted((SAMPLE / "summer").iterdir())[0]
            shutil.copy(source, os.path.join(os.fsencode(folder), b"caf\xe9.png"))
            names = openable.list_images(folder)
            self.assertEqual(len(names), 1)
            self.assertEqual(os.fsencode(names[0]), os.path.join(os.fsencode(folder), b"caf\xe9.png"))
            np.testing.assert_array_equal(openable.read_image(names[0]),
                                          openable.read_image(str(source)))
            with self.assertRaises(ValueError):
                openable.read_image(None)
        finally:
            shutil.rmtree(folder)

    def test_trajectory_timestamps_must_increase(self):
        poses = np.tile(np.hstack([np.eye(3), np.zeros((3, 1))]), (3, 1, 1))
        with self.assertRaises(ValueError) as caught:
            snaps.Trajectory(poses, timestamps=[0.0, 0.2, 0.1], format="tum")
        self.assertIn("strictly increasing", str(caught.exception))
        with self.assertRaises(ValueError):
            snaps.Trajectory(poses, frame_ids=[0, 2, 2])
        snaps.Trajectory(poses, timestamps=[0.0, 0.1, 0.2], format="tum")


if __name__ == "__main__":
    unittest.main()
