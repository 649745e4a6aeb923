"""Wrong conventions and runs that yield nothing, tried from Python as a new user would: a
world-to-camera trajectory read as camera-to-world, a similarity given as distances, the KITTI
format with frame ids, a ground truth with no true place, a missing ground-truth file, a square
matrix with a ground truth of two traversals; and the defaults Python shares with the programs
(their option table, as --help-keys prints it)."""
import json
import re
import subprocess
import unittest
import warnings

import numpy as np

import openable
from openable import snaps
from support import (KITTI_TRAJECTORIES, SAMPLE, TempDirTestCase, program, read_json, require,
                     run, settings)

VO = KITTI_TRAJECTORIES / "vo_so_dso" / "seq00" / "poses_history_file.txt"
TRUTH = KITTI_TRAJECTORIES / "poses" / "00.txt"
PAIRS = KITTI_TRAJECTORIES / "loop_pairs" / "groundTruth_KITTI00.pairs.csv"


def caught(function, *args, **kwargs):
    """(result, [warning messages]) of a call, every warning recorded."""
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        result = function(*args, **kwargs)
    return result, [str(w.message) for w in seen]


def table_defaults(name):
    """{key: default} of a program's option table, as `name --help-keys` prints it."""
    text = subprocess.run([program(name), "--help-keys"], stdout=subprocess.PIPE, text=True,
                          check=True).stdout
    out = {}
    for line in text.splitlines():
        m = re.match(r"^  (\w+)(?: \(new\))?\s+\[.*, default (.*)\]$", line)
        if m:
            value = m.group(2)
            out[m.group(1)] = value[1:-1] if value.startswith('"') else float(value)
    return out


def signature_defaults(function):
    """{keyword: default} of the signature that opens a function's docstring."""
    signature = function.__doc__.split("->")[0]
    out = {}
    for name, value in re.findall(r"(\w+)=(\"[^\"]*\"|[^,\s)]+)", signature):
        if value.startswith('"'):
            out[name] = value[1:-1]
        elif value in ("True", "False"):
            out[name] = float(value == "True")
        elif value != "None":
            out[name] = float(value)
    return out


class ConventionHintTest(unittest.TestCase):
    """SO-DSO's keyframes are world-to-camera: read without world_to_camera, the trajectory is
    hundreds of metres from the ground truth's route even after alignment."""

    @classmethod
    def setUpClass(cls):
        require(VO)
        cls.truth = snaps.read_trajectory(str(TRUTH))

    def test_trajectory_error_hints_at_world_to_camera(self):
        wrong = snaps.read_trajectory(str(VO), "kitti-id")
        error, said = caught(snaps.trajectory_error, wrong, self.truth)
        self.assertEqual(len(said), 1, said)
        # The distance the hint gives is the aligned mean error, computed here separately.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            aligned = snaps.trajectory_error(wrong, self.truth, align=True)
        self.assertIn("the estimate is %.1f m from the ground truth on average even after "
                      "alignment" % aligned.mean, said[0])
        self.assertIn("Check world_to_camera (True when", said[0])
        self.assertGreater(error.mean, 100)
        # Read as SO-DSO writes it: a drift of about 10 m, nothing to hint at.
        right = snaps.read_trajectory(str(VO), "kitti-id", world_to_camera=True)
        error, said = caught(snaps.trajectory_error, right, self.truth)
        self.assertEqual(said, [])
        self.assertLess(error.mean, 20)

    def test_the_chain_hints_in_its_keys(self):
        keys = {"Snaps_trajectory": str(VO), "Snaps_trajectory_format": "kitti-id",
                "Snaps_ground_truth": str(TRUTH), "Snaps_loops": "pairs",
                "Snaps_loops_file": str(PAIRS), "Snaps_drop_outside": True,
                "Snaps_corrector": "discounted"}
        chain, said = caught(snaps.run, settings=keys)
        self.assertEqual(len(said), 1, said)
        self.assertIn("Check Snaps_world_to_camera (1 when", said[0])
        # The report wraps its lines: compared word by word.
        self.assertIn(" ".join(("Hint: " + said[0]).split()), " ".join(chain.report().split()))
        chain, said = caught(snaps.run, settings=dict(keys, Snaps_world_to_camera=True))
        self.assertEqual(said, [])

    def test_kitti_with_frame_ids_is_named(self):
        with self.assertRaises(openable.InputError) as e:
            snaps.read_trajectory(str(VO))
        self.assertIn(":1: line has 13 numbers; expected 12 numbers", str(e.exception))
        self.assertIn("a frame number then 12 numbers is the format kitti-id", str(e.exception))
        with self.assertRaises(openable.InputError) as e:
            snaps.read_trajectory(str(TRUTH), "kitti-id")
        self.assertIn("12 numbers without a frame number are the format kitti", str(e.exception))


class EvaluationWarningsTest(TempDirTestCase):
    """A real matrix of the bundled sample (winter against summer), as distances and turned
    into a similarity."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        run("Test_OpenABLE", ["--quiet"] + settings(
            "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=%s" % (SAMPLE / "winter"),
            "Image_sequences=10", "Npy_name=m.npy"), cls.tmp)
        cls.m = np.load(cls.tmp / "m.npy")
        cls.frames = cls.m.shape[0] // 2

    def evaluate(self, matrix, **kwargs):
        return caught(openable.evaluate, matrix, aligned=True, reference_frames=self.frames,
                      **kwargs)

    def test_a_similarity_looks_reversed(self):
        distances, said = self.evaluate(self.m)
        self.assertEqual(said, [])
        self.assertEqual(distances.warnings, [])
        similarity = np.where(np.isfinite(self.m), 1 - self.m, np.inf).astype(np.float32)
        for score in ("distance", "ratio"):
            r, said = self.evaluate(similarity, score=score)
            self.assertLess(r.auc, 0.1)
            self.assertEqual(len(said), 1, said)
            self.assertEqual(r.warnings, said)
            self.assertIn("the ranking looks reversed: per-query AUC %.3f with the smallest "
                          "values as best matches" % r.auc, said[0])
            self.assertIn("the matrix looks like a similarity", said[0])
        # The reversed matrix of 1 - M ranks as M: the AUC the warning gives is M's.
        r, said = self.evaluate(similarity)
        self.assertIn(", %.3f with the largest" % distances.auc, said[0])

    def test_no_true_place_is_said(self):
        r, said = caught(openable.evaluate, self.m[:self.frames, :self.frames],
                         pairs=[[150, 100], [200, 160]], exclusion=60)
        self.assertEqual(r.positive_queries, 0)
        self.assertEqual(len(said), 1, said)
        self.assertIn("no query has a true place among its candidates (%d queries; 2 pairs"
                      % (self.frames - 60), said[0])

    def test_warnings_can_be_errors(self):
        similarity = np.where(np.isfinite(self.m), 1 - self.m, np.inf).astype(np.float32)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with self.assertRaises(UserWarning):
                openable.evaluate(similarity, aligned=True, reference_frames=self.frames)


class MessagesTest(unittest.TestCase):
    def test_missing_ground_truth_files_are_named(self):
        m = np.random.default_rng(3).random((10, 10)).astype(np.float32)
        for kind in ("vpr_bench", "vpr_tutorial", "pairs", "matrix"):
            path = "/nonexistent/ground_truth_%s.npy" % kind
            with self.assertRaises(openable.InputError) as e:
                openable.evaluate(m, truth_file=path, truth_type=kind, layout="query_reference")
            self.assertIn('"%s" does not exist' % path, str(e.exception))

    def test_two_traversals_are_asked_for_in_pythons_words(self):
        m = np.random.default_rng(4).random((10, 10)).astype(np.float32)
        for kwargs, what in (({"truth_file": "gt.npy", "truth_type": "vpr_bench"},
                              'truth_type: "vpr_bench"'),
                             ({"truth_file": "gt.npy", "truth_type": "vpr_tutorial"},
                              'truth_type: "vpr_tutorial"'),
                             ({"pairs": [[1, 2]], "protocol": "vpr_bench"},
                              'protocol: "vpr_bench"')):
            with self.assertRaises(openable.InputError) as e:
                openable.evaluate(m, **kwargs)
            text = str(e.exception)
            self.assertTrue(text.startswith(what + " needs two traversals, but the 10x10 matrix"),
                            text)
            self.assertIn('layout="query_reference"', text)
            self.assertIn("reference_frames=N", text)
            for key in ("Images_path_2", "Frame_mode", "Ground_truth"):
                self.assertNotIn(key, text)

    def test_config_keys_inside_a_message_take_the_argument_names(self):
        m = np.random.default_rng(5).random((10, 10)).astype(np.float32)
        with self.assertRaises(openable.InputError) as e:
            openable.evaluate(m, truth_file=str(TRUTH), truth_type="kitti",
                              layout="query_reference")
        self.assertIn("with two traversals truth_file holds the reference poses",
                      str(e.exception))
        self.assertNotIn("Ground_truth", str(e.exception))


class DefaultsTest(TempDirTestCase):
    """Python's defaults are the programs': each keyword that is a Config.txt key defaults to
    that key's default in the option table, as the programs print it (--help-keys)."""

    EVALUATE = {"base": "Ground_truth_base", "first_frame": "Initial_image",
                "tolerance": "Tolerance", "exclusion": "Exclusion", "vicinity": "Vicinity",
                "radius": "Ground_truth_radius", "heading_limit": "Ground_truth_heading",
                "axes": "Ground_truth_axes", "score": "Match_score",
                "score_window": "Match_score_window", "accept_consistency": "Match_consistency",
                "sequence_length": "Image_sequences", "partial": "Sequence_partial",
                "direction": "Sequence_direction", "protocol": "Evaluation_protocol",
                "truth_file_soft": "Ground_truth_soft"}
    SNAPS = {
        snaps.read_trajectory: {"format": "Snaps_trajectory_format",
                                "world_to_camera": "Snaps_world_to_camera"},
        snaps.Trajectory: {"format": "Snaps_trajectory_format",
                           "world_to_camera": "Snaps_world_to_camera"},
        snaps.associate: {"time_tolerance": "Snaps_time_tolerance"},
        snaps.trajectory_error: {"time_tolerance": "Snaps_time_tolerance"},
        snaps.loops_from_csv: {"tolerance": "Snaps_keyframe_tolerance",
                               "drop_outside": "Snaps_drop_outside",
                               "middle_of_runs": "Snaps_middle_of_runs"},
        snaps.loops_from_matrix: {"threshold": "Snaps_matrix_threshold",
                                  "exclusion": "Snaps_frame_distance",
                                  "initial": "Initial_image",
                                  "tolerance": "Snaps_keyframe_tolerance"},
        snaps.closed_loops: {"pause": "Snaps_pause"},
        snaps.apply_discounted_update: {"discount_length": "Snaps_discount_length"},
        snaps.correct_discounted: {"discount_length": "Snaps_discount_length",
                                   "pause": "Snaps_pause"},
        snaps.correct_pose_graph: {
            "odometry_translation_weight": "Snaps_odometry_translation_weight",
            "odometry_rotation_weight": "Snaps_odometry_rotation_weight",
            "loop_weight": "Snaps_loop_weight", "robust_kernel": "Snaps_robust_kernel",
            "robust_scale": "Snaps_robust_scale"},
    }

    def check(self, function, names, table):
        python = signature_defaults(function)
        for name, key in names.items():
            expected = table[key]
            if key == "Sequence_direction":  # read by number; Python takes its name
                expected = ["forward", "reverse", "both"][int(expected)]
            self.assertIn(name, python, "%s has no default for %s" % (function.__name__, name))
            self.assertEqual(python[name], expected, "%s: %s against %s" % (
                function.__name__, name, key))

    def test_signatures_carry_the_option_tables_defaults(self):
        table = table_defaults("Test_OpenABLE")
        self.check(openable.evaluate, self.EVALUATE, table)
        self.check(openable.unsupervised_criteria,
                   {k: self.EVALUATE[k] for k in ("sequence_length", "partial", "direction",
                                                  "exclusion", "score_window")}, table)
        snaps_table = table_defaults("openable_snaps")
        for function, names in self.SNAPS.items():
            self.check(function, names, snaps_table)

    def test_tolerance_and_layout_defaults_act_as_the_programs(self):
        run("Test_OpenABLE", ["--quiet"] + settings(
            "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=%s" % (SAMPLE / "winter"),
            "Image_sequences=10", "Npy_name=m.npy", "Ground_truth_type=aligned",
            "Evaluation_name=run"), self.tmp)
        m = np.load(self.tmp / "m.npy")
        frames = m.shape[0] // 2
        figures = read_json(self.tmp / "run.json")["runs"][0]["per_query"]
        table = table_defaults("Test_OpenABLE")
        default = openable.evaluate(m, aligned=True, reference_frames=frames)
        self.assertEqual(default.auc, openable.evaluate(
            m, aligned=True, reference_frames=frames, tolerance=int(table["Tolerance"])).auc)
        # The program's run, with its own default Tolerance, gives the same figures.
        self.assertAlmostEqual(default.auc, figures["auc"], places=6)
        self.assertAlmostEqual(default.recall_at_1, figures["recall_at_1"], places=6)
        # A square matrix without layout is one sequence, as openable_evaluate reads it.
        square = m[:frames, :frames]
        pairs = [[250, 10], [280, 40]]
        np.savetxt(self.tmp / "pairs.txt", pairs, fmt="%d", delimiter=",")
        np.save(self.tmp / "square.npy", square)
        done = run("openable_evaluate", ["--matrix", "square.npy", "--gt-type", "pairs",
                                         "--ground-truth", "pairs.txt", "--json"], self.tmp)
        cli = json.loads(done.stdout)["evaluation"]["runs"][0]
        mine = openable.evaluate(square, pairs=pairs)
        self.assertEqual(mine.layout, "loop_closure")
        self.assertEqual(cli["per_query"]["queries"], mine.queries)
        self.assertAlmostEqual(cli["per_query"]["auc"], mine.auc, places=6)

    def test_loops_from_csv_keeps_what_the_program_keeps(self):
        require(VO)
        trajectory = snaps.read_trajectory(str(VO), "kitti-id", world_to_camera=True)
        default = snaps.loops_from_csv(str(PAIRS), trajectory, drop_outside=True)
        chain = snaps.run(settings={
            "Snaps_trajectory": str(VO), "Snaps_trajectory_format": "kitti-id",
            "Snaps_world_to_camera": True, "Snaps_loops": "pairs",
            "Snaps_loops_file": str(PAIRS), "Snaps_drop_outside": True,
            "Snaps_corrector": "discounted"})
        self.assertEqual(default, chain.loops)
        every = snaps.loops_from_csv(str(PAIRS), trajectory, drop_outside=True,
                                     middle_of_runs=False)
        self.assertGreater(len(every), 10 * len(default))
        self.assertEqual(default, snaps.middle_of_runs(every, trajectory))


if __name__ == "__main__":
    unittest.main()
