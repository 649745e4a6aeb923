"""--json on the command-line programs: one JSON object on stdout that scripts can load, whose
figures agree with the files the run wrote and with values recomputed here with NumPy."""
import json
import os
import subprocess
import unittest
from pathlib import Path

import numpy as np

from support import (KITTI_TRAJECTORIES, SAMPLE, SOURCE_DIR, TempDirTestCase, program,
                     read_json, require, run)

CONFIG = SOURCE_DIR / "config" / "Config.txt"


def sample_run(tmp, *extra):
    """Test_OpenABLE on the bundled sample (config/Config.txt), outputs under tmp/out."""
    return run("Test_OpenABLE",
               [CONFIG, "--quiet", "--set", "Images_path=%s" % (SAMPLE / "summer"),
                "--set", "Images_path_2=%s" % (SAMPLE / "winter"),
                "--set", "Txt_name=", "--set", "Png_name=", "--set", "Npy_name=out/m.npy",
                "--set", "Evaluation_name=out/eval"] + list(extra), tmp)


class RunJsonTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.done = sample_run(cls.tmp, "--json")
        cls.report = json.loads(cls.done.stdout)  # the whole of stdout is one object

    def test_traversals_and_matrix(self):
        r = self.report
        self.assertEqual(r["program"], "Test_OpenABLE")
        frames = [len([f for f in os.listdir(SAMPLE / season) if f.endswith(".png")])
                  for season in ("summer", "winter")]
        self.assertEqual([t["frames"] for t in r["traversals"]], frames)
        self.assertEqual([t["first_row"] for t in r["traversals"]], [0, frames[0]])
        m = np.load(self.tmp / "out" / "m.npy")
        self.assertEqual((r["matrix"]["rows"], r["matrix"]["cols"]), m.shape)
        self.assertFalse(r["bounded"])
        self.assertIsNone(r["index"])
        # Eq. 9 with the configuration's Threshold (0.45): cells of M' below it.
        threshold = 0.45
        self.assertEqual(r["threshold_cells_below"], int(np.sum(m < threshold)))
        self.assertEqual(r["descriptors"][0]["name"], "LDB")
        self.assertEqual(r["descriptors"][0]["metric"], "Hamming")

    def test_evaluation_is_the_written_one(self):
        written = read_json(self.tmp / "out" / "eval.json")
        self.assertEqual(self.report["evaluation"]["runs"], written["runs"])
        self.assertEqual(self.report["evaluation"]["settings"], written["settings"])

    def test_written_files_exist_and_timings_add_up(self):
        for path in self.report["written"]:
            self.assertTrue((self.tmp / path).is_file(), path)
        t = self.report["timings"]
        parts = t["description"] + t["matching"] + t["sequences"] + t["export"]
        self.assertLessEqual(parts, t["total"] * 1.001 + 1e-3)
        self.assertEqual(t["frames"], sum(x["frames"] for x in self.report["traversals"]))

    def test_without_json_the_report_is_text(self):
        done = sample_run(self.tmp / "out", "--set", "Evaluation_name=")
        with self.assertRaises(ValueError):
            json.loads(done.stdout)
        self.assertIn("Timings (wall clock):", done.stdout)

    def test_evaluate_and_sweep(self):
        m = self.tmp / "out" / "m.npy"
        done = run("openable_evaluate",
                   ["--config", CONFIG, "--matrix", m, "--reference-frames", "300",
                    "--set", "Evaluation_name=", "--json"], self.tmp)
        evaluated = json.loads(done.stdout)
        self.assertEqual(evaluated["program"], "openable_evaluate")
        self.assertEqual(evaluated["written"], [])
        self.assertEqual(evaluated["evaluation"]["runs"][0]["per_query"],
                         self.report["evaluation"]["runs"][0]["per_query"])
        done = run("openable_sweep",
                   [CONFIG, "--quiet", "--set", "Images_path=%s" % (SAMPLE / "summer"),
                    "--set", "Images_path_2=%s" % (SAMPLE / "winter"),
                    "--vary", "Image_sequences=1,10", "--output", "out/sweep", "--json"],
                   self.tmp)
        swept = json.loads(done.stdout)
        self.assertEqual(swept["program"], "openable_sweep")
        self.assertEqual(len(swept["sweep"]["runs"]), 2)
        self.assertEqual(swept["sweep"], read_json(self.tmp / "out" / "sweep.json"))


class SavedMatrixSettingsTest(TempDirTestCase):
    """A matrix's settings file (m.npy.json) gives Python's openable.evaluate the keywords that
    reproduce the run's figures: here the across-conditions preset, which scores by ratio and
    accepts with a consistency partner, against the bundled sample's alignment."""

    def test_python_evaluates_a_saved_matrix_as_the_run_did(self):
        import openable

        preset = SOURCE_DIR / "config" / "presets" / "across_conditions.txt"
        done = run("Test_OpenABLE",
                   [preset, "--quiet", "--json", "--set", "Images_path=%s" % (SAMPLE / "summer"),
                    "--set", "Images_path_2=%s" % (SAMPLE / "winter"),
                    "--set", "Ground_truth_type=aligned", "--set", "Png_name=",
                    "--set", "Npy_name=out/m.npy"], self.tmp)
        report = json.loads(done.stdout)["evaluation"]["runs"][0]["per_query"]
        m = self.tmp / "out" / "m.npy"
        settings = openable.read_matrix_settings(m)
        self.assertEqual(settings["match_score"], "ratio")
        self.assertEqual(settings["reference_frames"], 300)
        result = openable.evaluate(openable.read_matrix(str(m)), **settings["python_evaluate"])
        self.assertAlmostEqual(result.auc, report["auc"], places=8)
        self.assertAlmostEqual(result.recall_at_1, report["recall_at_1"], places=8)
        self.assertAlmostEqual(result.max_f1, report["max_f1"], places=8)
        # Without the settings (the distance score, one sequence): other figures.
        plain = openable.evaluate(openable.read_matrix(str(m)), aligned=True, reference_frames=300)
        self.assertNotAlmostEqual(plain.auc, report["auc"], places=3)
        self.assertIsNone(openable.read_matrix_settings(self.tmp / "out" / "absent.npy"))
        (self.tmp / "out" / "bad.npy.json").write_text("[1]")
        with self.assertRaises(openable.InputError):
            openable.read_matrix_settings(self.tmp / "out" / "bad.npy")
        # Beside a matrix of another size: refused naming both sizes, as openable_evaluate does.
        import numpy
        other = self.tmp / "out" / "other.npy"
        numpy.save(other, numpy.zeros((80, 80), numpy.float32))
        (self.tmp / "out" / "other.npy.json").write_bytes((self.tmp / "out" / "m.npy.json").read_bytes())
        with self.assertRaises(openable.InputError) as caught:
            openable.read_matrix_settings(other)
        self.assertIn("80x80, but its settings file", str(caught.exception))
        self.assertIn("was written with a 600x600 matrix (traversals of 300 and 300 frames)",
                      str(caught.exception))


class SnapsJsonTest(TempDirTestCase):
    def test_snaps(self):
        require(KITTI_TRAJECTORIES)
        d = KITTI_TRAJECTORIES
        trajectory = d / "vo_so_dso" / "seq00" / "poses_history_file.txt"
        done = run("openable_snaps",
                   ["--quiet", "--json", "--set", "Snaps_trajectory=%s" % trajectory,
                    "--set", "Snaps_trajectory_format=kitti-id",
                    "--set", "Snaps_world_to_camera=1", "--set", "Snaps_loops=pairs",
                    "--set", "Snaps_loops_file=%s" % (d / "loop_pairs" /
                                                      "groundTruth_KITTI00.pairs.csv"),
                    "--set", "Snaps_drop_outside=1", "--set", "Snaps_output_name=out/k00"],
                   self.tmp)
        report = json.loads(done.stdout)
        self.assertEqual(report["program"], "openable_snaps")
        with open(trajectory) as f:
            poses = sum(1 for line in f if line.strip())
        self.assertEqual(report["snaps"]["poses"], poses)
        self.assertEqual(report["snaps"], read_json(self.tmp / "out" / "k00.json"))
        for path in report["written"]:
            self.assertTrue((self.tmp / path).is_file(), path)


if __name__ == "__main__":
    unittest.main()
