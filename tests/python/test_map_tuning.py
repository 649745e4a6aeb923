"""Maps that choose their settings from their own sessions and accept only right places:
openable_map add with the auto preset, tune, info and query (its CSV, JSON and evaluation), the
Python detector's tune() and query() against the program's, on the bundled Nordland sample and,
when present, the shared Nordland seasons (the example of openable_map --help). Places are
judged here from the file names: frame i of winter is frame i of summer (the aligned ground
truth, +-2 frames)."""
import csv
import json
import subprocess
import unittest

import openable
from support import NORDLAND, SAMPLE, SOURCE_DIR, TempDirTestCase, program, require, run

AUTO = SOURCE_DIR / "config" / "presets" / "auto.txt"
TOLERANCE = 2


def two_seasons(tmp, root, name):
    """A map of root/summer then root/winter made with the auto preset, tuned; its path and
    what tune printed."""
    path = tmp / name
    run("openable_map", ["add", path, "--images", root / "summer", "--session", "summer",
                         "--config", AUTO, "--quiet"], tmp)
    run("openable_map", ["add", path, "--images", root / "winter", "--session", "winter",
                         "--quiet"], tmp)
    return path, run("openable_map", ["tune", path], tmp).stdout


def query_rows(tmp, path, root, prefix, *extra):
    """openable_map query of root/winter against the summer session, written to prefix.*; the
    rows of prefix.csv."""
    run("openable_map", ["query", path, "--images", root / "winter", "--session", "summer",
                         "--output", tmp / prefix, "--quiet"] + list(extra), tmp)
    with open(tmp / (prefix + ".csv")) as f:
        return list(csv.DictReader(f))


def figures(rows):
    """R@1 (best match within the tolerance), accepted answers and the wrong ones among them."""
    right = [r["frame"] != "" and abs(int(r["frame"]) - i) <= TOLERANCE
             for i, r in enumerate(rows)]
    accepted = [i for i, r in enumerate(rows) if r["accepted"] == "1"]
    return sum(right) / len(rows), len(accepted), sum(1 for i in accepted if not right[i])


class SampleMapTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.map, cls.tune_output = two_seasons(cls.tmp, SAMPLE, "sample.map")
        cls.rows = query_rows(cls.tmp, cls.map, SAMPLE, "winter",
                              "--set", "Ground_truth_type=aligned")

    def test_tune_keeps_the_choice_and_info_shows_it(self):
        self.assertIn("<- chosen", self.tune_output)
        info = json.loads(run("openable_map", ["info", self.map, "--json"], self.tmp).stdout)
        self.assertEqual(info["format_version"], 3)
        self.assertEqual(info["descriptors"], ["HOG", "SIFT", "LDB", "SAD"])
        tuning = info["tuning"]
        self.assertEqual(tuning["verdict"], "reliable")
        self.assertEqual((tuning["reference"], tuning["query"]), ("summer", "winter"))
        self.assertEqual(len(tuning["candidates"]), 15)
        ranked = sorted(tuning["candidates"], key=lambda c: c["rank"])
        self.assertEqual(ranked[0]["settings"], tuning["chosen"])
        self.assertTrue(all(a["agreement"] >= b["agreement"] for a, b in zip(ranked, ranked[1:])))
        text = run("openable_map", ["info", self.map], self.tmp).stdout
        self.assertIn("reliable: ", text)
        self.assertIn(tuning["chosen"], text)

    def test_the_auto_mode_chooses_alike_from_the_same_frames(self):
        done = run("Test_OpenABLE", [AUTO, "--json", "--set", "Images_path=%s" % (SAMPLE / "summer"),
                                     "--set", "Images_path_2=%s" % (SAMPLE / "winter"),
                                     "--set", "Npy_name=", "--set", "Png_name=",
                                     "--set", "Evaluation_name="], self.tmp)
        batch = json.loads(done.stdout)["auto"]
        info = json.loads(run("openable_map", ["info", self.map, "--json"], self.tmp).stdout)
        self.assertEqual(info["tuning"]["chosen"], batch["chosen"])
        mine = {c["settings"]: c for c in info["tuning"]["candidates"]}
        # Every candidate but DenseVLAD's, whose vocabulary a map does not keep.
        kept = [c for c in batch["candidates"] if "DenseVLAD" not in c["settings"]]
        self.assertEqual(len(kept), len(mine))
        for c in kept:
            self.assertAlmostEqual(mine[c["settings"]]["consistency"], c["consistency"], places=9)

    def test_every_accepted_match_is_right(self):
        # No worse than the batch run's figures on this sample (R@1 0.833, all accepted right).
        recall, accepted, wrong = figures(self.rows)
        self.assertGreaterEqual(recall, 0.833)
        self.assertGreater(accepted, 100)
        self.assertEqual(wrong, 0)
        evaluation = json.load(open(self.tmp / "winter_eval.json"))
        run_figures = evaluation["runs"][0]["per_query"]
        self.assertAlmostEqual(run_figures["recall_at_1"], recall, places=9)

    def test_outputs_say_the_same(self):
        document = json.load(open(self.tmp / "winter.json"))
        self.assertEqual(len(document["queries"]), len(self.rows))
        for q, r in zip(document["queries"], self.rows):
            self.assertEqual(q["query"], r["query"])
            self.assertEqual(str(q["frame"]), r["frame"])
            self.assertEqual(q["accepted"], r["accepted"] == "1")
            self.assertEqual(q["confirmed"], r["confirmed"] == "1")
            self.assertTrue(q["confirmed"] or not q["accepted"])
        self.assertTrue(document["uses_tuning"])
        self.assertTrue((self.tmp / "winter.html").stat().st_size > 10000)

    def test_python_tunes_and_queries_as_the_program(self):
        options = openable.OnlineDetector.open(str(self.map)).options
        fresh = openable.OnlineDetector(descriptor="HOG", kept_descriptors="SIFT+LDB+SAD")
        for season in ("summer", "winter"):
            fresh.start_session(season)
            fresh.add_images_to_map([openable.read_image(p)
                                     for p in sorted((SAMPLE / season).glob("*.png"))])
        tuning = fresh.tune()
        info = json.loads(run("openable_map", ["info", self.map, "--json"], self.tmp).stdout)
        self.assertEqual(tuning["chosen"], info["tuning"]["chosen"])
        self.assertEqual(fresh.options["sequence_length"], options["sequence_length"])
        self.assertTrue(fresh.uses_tuning)
        winter = fresh.descriptors[len(fresh.descriptors) // 2:]
        answers = fresh.query(winter, "summer")
        for a, r in zip(answers, self.rows):
            self.assertEqual(a[0]["frame"], int(r["frame"]))
            self.assertEqual(a[0]["accepted"], r["accepted"] == "1")

    def test_a_missing_map_is_named(self):
        done = subprocess.run([program("openable_map"), "query", str(self.tmp / "absent.map"),
                               "--images", str(SAMPLE / "winter")], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
        self.assertEqual(done.returncode, 1)
        self.assertEqual(done.stderr.count("\n"), 1, done.stderr)
        self.assertIn("no map at", done.stderr)
        self.assertIn("create one with openable_map add", done.stderr)


class PresetMapTest(TempDirTestCase):
    """A map made with the across-conditions preset: a fused descriptor (HOG+LDB), whose
    search (L = 40, the ratio <= 0.9, confirmed) the map keeps for its queries."""

    def test_fused_preset_map_keeps_its_search(self):
        preset = SOURCE_DIR / "config" / "presets" / "across_conditions.txt"
        path = self.tmp / "fused.map"
        run("openable_map", ["add", path, "--images", SAMPLE / "summer", "--session", "summer",
                             "--config", preset, "--quiet"], self.tmp)
        info = json.loads(run("openable_map", ["info", path, "--json"], self.tmp).stdout)
        self.assertEqual(info["descriptors"], ["HOG", "LDB"])
        self.assertEqual(info["settings"]["search_sequence_length"], "40")
        self.assertEqual(info["settings"]["search_score"], "ratio")
        self.assertIsNone(info["tuning"])
        rows = query_rows(self.tmp, path, SAMPLE, "fused")
        recall, accepted, wrong = figures(rows)
        self.assertGreaterEqual(recall, 0.8)
        self.assertGreater(accepted, 100)
        self.assertEqual(wrong, 0)
        # Told otherwise on the command line: L = 10, the score alone.
        other = query_rows(self.tmp, path, SAMPLE, "l10", "--set", "Image_sequences=10",
                           "--set", "Match_consistency=0")
        document = json.load(open(self.tmp / "l10.json"))
        self.assertIn("L = 10", document["search"])
        self.assertNotIn("confirmed by", document["search"])
        self.assertNotEqual([r["frame"] for r in other], [r["frame"] for r in rows])


class UnrelatedMapTest(TempDirTestCase):
    """Two sessions of different stretches of the route: tune says UNRELIABLE, nothing is
    accepted."""

    def test_unreliable_map_accepts_nothing(self):
        path = self.tmp / "unrelated.map"
        summer = sorted((SAMPLE / "summer").glob("*.png"))[:150]
        winter = sorted((SAMPLE / "winter").glob("*.png"))[150:]
        for name, files in (("a", summer), ("b", winter)):
            folder = self.tmp / name
            folder.mkdir()
            for f in files:
                (folder / f.name).symlink_to(f)
        run("openable_map", ["add", path, "--images", self.tmp / "a", "--session", "a",
                             "--quiet"], self.tmp)
        run("openable_map", ["add", path, "--images", self.tmp / "b", "--session", "b",
                             "--quiet"], self.tmp)
        out = run("openable_map", ["tune", path], self.tmp).stdout
        self.assertIn("UNRELIABLE", out)
        done = run("openable_map", ["query", path, "--images", self.tmp / "b", "--session", "a",
                                   "--json"], self.tmp)
        answers = json.loads(done.stdout)["queries"]
        self.assertEqual(sum(q["accepted"] for q in answers), 0)
        text = run("openable_map", ["query", path, "--images", self.tmp / "b", "--session", "a"],
                   self.tmp)
        self.assertIn("UNRELIABLE", text.stderr)


class NordlandSeasonsTest(TempDirTestCase):
    """The example of openable_map --help on the shared Nordland seasons: winter queried
    against summer with the map's own settings."""

    def test_right_places_and_only_right_ones(self):
        require(NORDLAND)
        path, _ = two_seasons(self.tmp, NORDLAND, "nordland.map")
        recall, accepted, wrong = figures(query_rows(self.tmp, path, NORDLAND, "winter"))
        self.assertGreaterEqual(recall, 0.9)
        self.assertGreater(accepted, 1000)
        self.assertEqual(wrong, 0)


if __name__ == "__main__":
    unittest.main()
