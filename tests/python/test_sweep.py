"""openable.sweep against openable_sweep (the same runs, the same figures) and against single
runs of openable.evaluate on the matrices of Test_OpenABLE, on the bundled sample."""
import _thread
import os
import threading
import unittest

import openable
from support import SAMPLE, SOURCE_DIR, TempDirTestCase, read_json, run

SETTINGS = {"Images_path": str(SAMPLE / "summer"), "Images_path_2": str(SAMPLE / "winter"),
            "Ground_truth_type": "aligned", "Txt_name": "", "Npy_name": "", "Png_name": "",
            "Evaluation_name": ""}
CONFIG = SOURCE_DIR / "config" / "Config.txt"


def figures(run_object):
    keys = ("auc", "recall_at_100p", "max_f1", "recall_at_1", "recall_at_5", "recall_at_10")
    return {k: run_object[k] for k in keys}


class SweepTest(TempDirTestCase):
    def test_same_runs_as_the_program(self):
        result = openable.sweep(CONFIG, settings=SETTINGS,
                                vary={"Image_descriptor": ["LDB", "HOG"],
                                      "Image_sequences": [1, 5],
                                      "Match_score": "distance,ratio"},
                                output=self.tmp / "py")
        self.assertEqual(len(result.runs), 8)
        self.assertEqual(result.descriptions, 2)
        self.assertEqual(result.frame_reads, 1)
        self.assertEqual(len(result.written), 3)
        args = [CONFIG, "--quiet", "--vary", "Image_descriptor=LDB,HOG",
                "--vary", "Image_sequences=1,5", "--vary", "Match_score=distance,ratio",
                "--output", "cli"]
        for k, v in SETTINGS.items():
            args += ["--set", "%s=%s" % (k, v)]
        run("openable_sweep", args, self.tmp)
        cli = read_json(self.tmp / "cli.json")
        py = read_json(self.tmp / "py.json")
        self.assertEqual(len(cli["runs"]), 8)
        for a, b, c in zip(cli["runs"], py["runs"], result.runs):
            self.assertEqual(a["settings"], b["settings"])
            self.assertEqual(a["settings"], c["settings"])
            self.assertEqual(a["per_query"], b["per_query"])
            for k, v in figures(a["per_query"]).items():  # the JSON keeps 9 digits
                self.assertAlmostEqual(v, c[k], places=8, msg=k)
        # Ranked best first by AUC.
        aucs = [r["auc"] for r in result.runs]
        self.assertEqual(aucs, sorted(aucs, reverse=True))

    def test_matches_evaluate_on_the_runs_matrix(self):
        # One combination, recomputed by hand: Test_OpenABLE's matrix, evaluated by
        # openable.evaluate with the same score.
        result = openable.sweep(CONFIG, settings=SETTINGS,
                                vary={"Match_score": ["ratio"], "Image_sequences": [5]})
        args = [CONFIG, "--quiet", "--set", "Image_sequences=5", "--set", "Match_score=ratio"]
        for k, v in SETTINGS.items():
            args += ["--set", "%s=%s" % (k, v)]
        args += ["--set", "Npy_name=m.npy", "--set", "Ground_truth_type="]
        run("Test_OpenABLE", args, self.tmp)
        matrix = openable.read_matrix(str(self.tmp / "m.npy"))
        # Two traversals of 300 frames, aligned: query q is reference q.
        ev = openable.evaluate(matrix, aligned=True, reference_frames=300, tolerance=2,
                               score="ratio", score_window=10)
        self.assertAlmostEqual(result.runs[0]["auc"], ev.auc, places=6)
        self.assertAlmostEqual(result.runs[0]["recall_at_100p"], ev.recall_at_100p, places=6)
        self.assertAlmostEqual(result.runs[0]["recall_at_1"], ev.recall_at_1, places=6)

    def test_ctrl_c_stops_a_sweep_between_runs(self):
        # The sweep's own lines ("run 2 of 40") go to stderr: a reader thread presses Ctrl-C
        # (interrupt_main) when it sees the second run start. KeyboardInterrupt must then end
        # the call before its last run; counted in runs, not in seconds.
        read_fd, write_fd = os.pipe()
        saved = os.dup(2)
        os.dup2(write_fd, 2)
        os.close(write_fd)
        lines = []

        def reader():
            with os.fdopen(read_fd, "r", errors="replace") as stream:
                for line in stream:
                    lines.append(line)
                    if "run 2 of 40" in line:
                        _thread.interrupt_main()

        thread = threading.Thread(target=reader)
        thread.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                openable.sweep(CONFIG, settings=SETTINGS, quiet=False,
                               vary={"Image_sequences": list(range(1, 41))})
        finally:
            os.dup2(saved, 2)  # closes the pipe's last write end: the reader sees its end
            os.close(saved)
            thread.join()
        started = [line for line in lines if " of 40: " in line]
        self.assertGreaterEqual(len(started), 2)
        self.assertLess(len(started), 40)

    def test_bad_values_raise_one_line(self):
        with self.assertRaises(openable.InputError) as caught:
            openable.sweep(CONFIG, settings=SETTINGS, vary={"Image_sequences": [1, 0]})
        self.assertIn("Image_sequences", str(caught.exception))
        self.assertIn('"0"', str(caught.exception))
        with self.assertRaises(openable.InputError) as caught:
            openable.sweep(CONFIG, settings=SETTINGS, vary={"Image_sequences": [1]},
                           rank_by="speed")
        self.assertIn("rank_by", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
