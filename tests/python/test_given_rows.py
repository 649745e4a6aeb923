"""Features computed elsewhere (Descriptors_path, Descriptors_path_2): rows saved with NumPy give
the run the matrix it computes from the same rows described by itself, float32 rows by L2 and
uint8 rows by Hamming; rows that do not fit the frames are refused in one line."""
import json
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

    def test_pythons_sweep_runs_on_given_rows(self):
        """openable.sweep over sequence lengths of given HOG rows: each run's AUC is that of the
        same run on HOG rows the run describes."""
        def sweep(**given):
            return {r["settings"]["Image_sequences"]: r["auc"] for r in openable.sweep(
                str(CONFIG), settings={"Images_path": str(SAMPLE / "summer"),
                                       "Images_path_2": str(SAMPLE / "winter"),
                                       "Ground_truth_type": "aligned", "Tolerance": "2",
                                       **given},
                vary={"Image_sequences": [1, 10]}).runs}
        given = sweep(Descriptors_path=str(self.tmp / "HOG_summer.npy"),
                      Descriptors_path_2=str(self.tmp / "HOG_winter.npy"))
        described = sweep(Image_descriptor="HOG")
        self.assertEqual(sorted(given), sorted(described))
        for length, auc in described.items():
            self.assertAlmostEqual(given[length], auc, places=9)

    def test_the_auto_mode_chooses_the_matching_of_given_rows(self):
        """With Descriptors_path the auto mode's default candidates are the default's matchings
        (sequences, contrast enhancement); each candidate's criteria are those of the same
        candidate on the same rows described by the run."""
        auto = SOURCE_DIR / "config" / "presets" / "auto.txt"

        def auto_run(*pairs):
            done = run("Test_OpenABLE", [auto, "--quiet", "--json"] + settings(
                "Images_path=%s" % (SAMPLE / "summer"),
                "Images_path_2=%s" % (SAMPLE / "winter"), *QUIET, "Npy_name=", *pairs),
                self.tmp)
            return json.loads(done.stdout)["auto"]
        given = auto_run("Descriptors_path=HOG_summer.npy", "Descriptors_path_2=HOG_winter.npy")
        described = auto_run(
            "Auto_candidates=Image_descriptor=HOG Image_sequences=10,20,40 | "
            "Image_descriptor=HOG Contrast_enhancement=1 Image_sequences=10,20,40")
        self.assertEqual(len(given["candidates"]), 6)
        figures = lambda a: sorted(
            (c["settings"].replace("Image_descriptor=HOG ", ""), round(c["consistency"], 6),
             round(c["distinctiveness"], 6)) for c in a["candidates"])
        self.assertEqual(figures(given), figures(described))
        self.assertEqual(given["chosen"], described["chosen"].replace("Image_descriptor=HOG ", ""))
        # A candidate naming a descriptor cannot apply to given rows: one line.
        done = subprocess.run(
            [program("Test_OpenABLE"), str(auto), "--quiet"] + settings(
                "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=%s" % (SAMPLE / "winter"),
                *QUIET, "Npy_name=", "Descriptors_path=HOG_summer.npy",
                "Descriptors_path_2=HOG_winter.npy",
                "Auto_candidates=Image_descriptor=LDB Image_sequences=10"),
            cwd=str(self.tmp), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
        self.assertIn("sets Image_descriptor, but the rows come from Descriptors_path",
                      done.stderr)

    def test_a_map_of_given_rows_answers_as_brute_force(self):
        """openable_map add/query --descriptors: each winter row's nearest summer row by L2
        (L = 1, the distance score), as NumPy finds it."""
        summer = np.load(self.tmp / "HOG_summer.npy")
        winter = np.load(self.tmp / "HOG_winter.npy")

        def map_tool(*args):
            return subprocess.run([program("openable_map")] + [str(a) for a in args],
                                  cwd=str(self.tmp), stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True)
        done = map_tool("add", "rows.map", "--descriptors", "HOG_summer.npy", "--images",
                        SAMPLE / "summer", "--session", "summer", "--set", "Image_sequences=1",
                        "--set", "Match_score=distance", "--quiet")
        self.assertEqual(done.returncode, 0, done.stderr)
        done = map_tool("add", "rows.map", "--descriptors", "HOG_winter.npy", "--session",
                        "winter", "--quiet")
        self.assertEqual(done.returncode, 0, done.stderr)
        info = json.loads(map_tool("info", "rows.map", "--json").stdout)
        self.assertEqual(info["descriptors"], ["NPY"])
        self.assertEqual([s["frames"] for s in info["sessions"]], [300, 300])
        done = map_tool("query", "rows.map", "--descriptors", "HOG_winter.npy", "--session",
                        "summer", "--json")
        self.assertEqual(done.returncode, 0, done.stderr)
        queries = json.loads(done.stdout)["queries"]
        d = np.sqrt(((winter[:, None, :].astype(np.float64) - summer[None, :, :]) ** 2).sum(2))
        self.assertEqual([q["frame"] for q in queries], list(np.argmin(d, axis=1)))
        self.assertEqual(queries[5]["query"], "row 5")
        # From Python: the map opened with its own settings answers the rows alike.
        detector = openable.OnlineDetector.open(str(self.tmp / "rows.map"))
        self.assertEqual(detector.channels, ["NPY"])
        results = detector.query(winter, sessions="summer")
        self.assertEqual([r[0]["frame"] for r in results], [q["frame"] for q in queries])
        # What does not fit is one line, and the map is kept.
        np.save(self.tmp / "narrow.npy", summer[:, :100])
        five = self.tmp / "five"
        five.mkdir()
        for p in sorted((SAMPLE / "summer").iterdir())[:5]:
            (five / p.name).symlink_to(p)
        before = (self.tmp / "rows.map").read_bytes()
        for args, expect in (
                (("query", "rows.map", "--images", SAMPLE / "winter"),
                 "expected --descriptors FILE.npy with the rows of these frames"),
                (("add", "rows.map", "--descriptors", "narrow.npy", "--session", "n"),
                 "100"),
                (("add", "rows.map", "--descriptors", "HOG_summer.npy", "--images", five,
                  "--session", "x"),
                 "holds 300 rows, but --images")):
            done = map_tool(*args)
            self.assertEqual(done.returncode, 1, done.stderr)
            self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
            self.assertIn(expect, done.stderr)
        self.assertEqual((self.tmp / "rows.map").read_bytes(), before)
        done = map_tool("add", "ldb.map", "--images", SAMPLE / "summer", "--session", "s",
                        "--quiet")
        self.assertEqual(done.returncode, 0, done.stderr)
        done = map_tool("add", "ldb.map", "--descriptors", "LDB_winter.npy", "--session", "w")
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("describes its frames itself", done.stderr)


if __name__ == "__main__":
    unittest.main()
