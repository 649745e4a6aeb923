"""Features computed elsewhere (Descriptors_path, Descriptors_path_2): rows saved with NumPy give
the run the matrix it computes from the same rows described by itself, float32 rows by L2 and
uint8 rows by Hamming; rows that do not fit the frames are refused in one line."""
import subprocess
import unittest

import numpy as np

import openable
from support import SAMPLE, SOURCE_DIR, TempDirTestCase, program, run, settings

CONFIG = SOURCE_DIR / "config" / "Config.txt"
QUIET = ["Png_name=", "Txt_name=", "Evaluation_name=", "Report_name="]


def traversal_rows(folder, descriptor):
    """The rows openable.describe_images gives the frames of `folder`, in the run's order."""
    names = sorted(p.name for p in folder.iterdir())
    images = [openable.read_image(str(folder / n)) for n in names]
    return openable.describe_images(images, descriptor=descriptor)


class GivenRowsTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        for descriptor in ("HOG", "LDB"):
            for t in ("summer", "winter"):
                np.save(cls.tmp / ("%s_%s.npy" % (descriptor, t)),
                        traversal_rows(SAMPLE / t, descriptor))

    def run_sample(self, *pairs):
        return run("Test_OpenABLE", [CONFIG, "--quiet"] + settings(
            "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=%s" % (SAMPLE / "winter"),
            *QUIET, *pairs), self.tmp)

    def test_given_rows_give_the_matrix_of_the_same_rows_described(self):
        for descriptor, dtype in (("HOG", np.float32), ("LDB", np.uint8)):
            self.assertEqual(np.load(self.tmp / ("%s_summer.npy" % descriptor)).dtype, dtype)
            self.run_sample("Image_descriptor=%s" % descriptor,
                            "Npy_name=described_%s.npy" % descriptor)
            self.run_sample("Descriptors_path=%s_summer.npy" % descriptor,
                            "Descriptors_path_2=%s_winter.npy" % descriptor,
                            "Npy_name=given_%s.npy" % descriptor)
            described = np.load(self.tmp / ("described_%s.npy" % descriptor))
            given = np.load(self.tmp / ("given_%s.npy" % descriptor))
            self.assertEqual(given.shape, (600, 600))
            # The same cells, bit for bit (cells without a value: +inf in both).
            self.assertTrue(np.array_equal(described, given), descriptor)

    def test_rows_that_do_not_fit_are_one_line(self):
        rows = np.load(self.tmp / "HOG_summer.npy")
        cases = {
            "short.npy": (rows[:299], "299 rows, but Images_path has 300 frames"),
            "double.npy": (rows.astype(np.float64), "dtype \"<f8\"; expected float32"),
            "empty.npy": (rows[:0], "holds no rows"),
            "flat.npy": (rows[0], "expected (frames, width)"),
            "nan.npy": (np.where(np.arange(300)[:, None] == 7, np.nan, rows).astype(np.float32),
                        "row 7 holds NaN at column 0"),
        }
        for name, (array, expect) in cases.items():
            np.save(self.tmp / name, array)
            done = subprocess.run(
                [program("Test_OpenABLE"), str(CONFIG), "--quiet"] + settings(
                    "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=", *QUIET,
                    "Descriptors_path=%s" % name, "Npy_name=none.npy"),
                cwd=str(self.tmp), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            self.assertEqual(done.returncode, 1, name + ": " + done.stderr)
            self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
            self.assertIn("Descriptors_path \"%s\"" % name, done.stderr)
            self.assertIn(expect, done.stderr)
            self.assertFalse((self.tmp / "none.npy").exists())
        # A second traversal without rows, and rows of two widths.
        for pairs, expect in (
                (["Descriptors_path=HOG_summer.npy"],
                 "Descriptors_path_2: empty, but the run has a second traversal"),
                (["Descriptors_path=HOG_summer.npy", "Descriptors_path_2=LDB_winter.npy"],
                 "Descriptors_path_2: rows of 32 uint8 values, Descriptors_path rows of 1764 "
                 "float32 values")):
            done = subprocess.run(
                [program("Test_OpenABLE"), str(CONFIG), "--quiet"] + settings(
                    "Images_path=%s" % (SAMPLE / "summer"),
                    "Images_path_2=%s" % (SAMPLE / "winter"), *QUIET, *pairs,
                    "Npy_name=none.npy"),
                cwd=str(self.tmp), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            self.assertEqual(done.returncode, 1, done.stderr)
            self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
            self.assertIn(expect, done.stderr)


if __name__ == "__main__":
    unittest.main()
