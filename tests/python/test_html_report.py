"""The HTML report (Report_name, openable_evaluate --report) opened in a real browser: Debian's
Chromium, headless. The page of the README demo loads with no message in the console, every
embedded image decodes, the screenshot is not blank, and the page holds what docs/output_formats.md
says, with the figures of the run's JSON. Skipped when chromium is not installed.
"""
import base64
import json
import os
import re
import shutil
import subprocess
import tempfile
import unittest
from html.parser import HTMLParser
from pathlib import Path

import numpy as np

import openable
import support

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
SECTIONS = ["settings", "figures", "pr", "matrix", "explore", "wrong-matches", "misses"]


def browse(page, out_dir, screenshot=None):
    """Loads `page` in headless Chromium: (DOM after load, console lines of the page)."""
    profile = tempfile.mkdtemp(prefix="chromium_", dir=str(out_dir))
    command = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--user-data-dir=" + profile, "--enable-logging=stderr", "--v=0",
               "--virtual-time-budget=5000", "--hide-scrollbars"]
    if screenshot:
        command += ["--window-size=1400,3000", "--screenshot=" + str(screenshot)]
    else:
        command += ["--dump-dom"]
    done = subprocess.run(command + [Path(page).resolve().as_uri()], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, timeout=120)
    if done.returncode != 0:
        raise AssertionError("chromium exited with %d:\n%s" % (done.returncode, done.stderr[-2000:]))
    console = [line for line in done.stderr.splitlines() if ":CONSOLE" in line]
    return done.stdout, console


class Page(HTMLParser):
    """Sections, tables (rows of cell texts) and images of a report."""

    def __init__(self, text):
        super().__init__()
        self.sections, self.images, self.tables = [], [], {}
        self.body = {}
        self._table, self._row, self._cell = None, None, None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "section":
            self.sections.append(a.get("id"))
        elif tag == "body":
            self.body = a
        elif tag == "img":
            self.images.append(a)
        elif tag == "table":
            self._table = a.get("id") or "%s-%d" % (a.get("data-kind", "table"), len(self.tables))
            self.tables[self._table] = []
        elif tag == "tr" and self._table:
            self._row = []
            self.tables[self._table].append(self._row)
        elif tag in ("td", "th") and self._row is not None:
            self._cell = ""

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._row.append(self._cell.strip())
            self._cell = None
        elif tag == "table":
            self._table, self._row = None, None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data


@unittest.skipIf(CHROMIUM is None, "chromium is not installed (apt-get install chromium)")
class DemoReport(support.TempDirTestCase):
    """The README demo (examples/demo.sh) with its report."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.report = cls.tmp / "report.html"
        preset = support.SOURCE_DIR / "config" / "presets" / "across_conditions.txt"
        support.run_sample(cls.tmp, "Ground_truth_type=aligned",
                           "Npy_name=%s" % (cls.tmp / "m.npy"), "Png_name=",
                           "Evaluation_name=%s" % (cls.tmp / "eval"), "Report_name=%s" % cls.report,
                           first=[preset])
        cls.text = cls.report.read_text()
        cls.page = Page(cls.text)
        cls.figures = support.read_json(cls.tmp / "eval.json")["runs"][0]["per_query"]

    def test_loads_in_chromium_without_console_messages(self):
        dom, console = browse(self.report, self.tmp)
        self.assertEqual(console, [])
        loaded = re.search(r'data-images-loaded="(\d+)/(\d+)"', dom)
        self.assertIsNotNone(loaded, "the page's load handler did not run")
        self.assertEqual(int(loaded.group(1)), len(self.page.images))
        self.assertEqual(int(loaded.group(2)), len(self.page.images))

    def test_screenshot_shows_the_page(self):
        shot = self.tmp / "shot.png"
        browse(self.report, self.tmp, screenshot=shot)
        image = openable.read_image(shot)
        self.assertEqual(image.shape[:2], (3000, 1400))
        # Not a blank page: the figures and frames give many grey levels.
        self.assertGreater(len(np.unique(np.round(image * 255))), 50)

    def test_structure_and_figures(self):
        self.assertEqual(self.page.sections, SECTIONS)
        rows = self.page.tables["figures-table"]
        header, values = rows[0], rows[1]
        for column, key in (("AUC", "auc"), ("R@100P", "recall_at_100p"), ("max F1", "max_f1"),
                            ("R@1", "recall_at_1"), ("R@5", "recall_at_5")):
            self.assertEqual(values[header.index(column)], "%.4f" % self.figures[key], column)
        self.assertEqual(int(values[header.index("queries")]), self.figures["queries"])
        settings = dict((r[0], r[1]) for r in self.page.tables["settings-table"][1:])
        self.assertEqual(settings["Image_descriptor"], '"HOG+LDB"')
        # Every image is embedded and decodes; the frames are the sample's PNGs themselves, the
        # explorer's thumbnail sheets JPEG.
        for image in self.page.images:
            kind = "jpeg" if image.get("class") == "sheet" else "png"
            self.assertTrue(image["src"].startswith("data:image/%s;base64," % kind), image["alt"])
        self.assertEqual(len([i for i in self.page.images if i.get("class") == "sheet"]), 2)
        self.assertNotIn("http", self.text)

    def test_worst_cases_are_the_runs_own(self):
        matrix = np.load(self.tmp / "m.npy")
        block = matrix[300:, :300]  # winter queries x summer references
        wrong = [t for k, t in self.page.tables.items() if k.startswith("wrong")][0]
        per_query = np.loadtxt(self.tmp / "eval_per_query.csv", delimiter=",", skiprows=1)
        self.assertGreater(len(wrong), 1)
        scores = []
        for row in wrong[1:]:
            query = int(re.search(r"query (\d+)", row[1]).group(1))
            answer = int(re.search(r"reference (\d+)", row[2]).group(1))
            true_place = int(re.search(r"reference (\d+)", row[3]).group(1))
            # Aligned ground truth, tolerance 2: wrong means more than 2 frames away.
            self.assertGreater(abs(answer - query), 2, row)
            self.assertEqual(true_place, query)
            # The answer is the query's smallest distance among the references.
            self.assertAlmostEqual(float(block[query, answer]), float(np.nanmin(block[query])),
                                   places=6)
            scores.append(float(re.search(r"score ([0-9.]+)", row[0]).group(1)))
        self.assertEqual(scores, sorted(scores))
        self.assertGreater(len(per_query), 0)
        # Three frames per case, shown at the sample's own size and content.
        frames = [i for i in self.page.images if i.get("class") == "frame"]
        self.assertEqual(len(frames) % 3, 0)
        self.assertTrue(frames)


@unittest.skipIf(CHROMIUM is None, "chromium is not installed (apt-get install chromium)")
class DamagedReport(support.TempDirTestCase):
    def test_an_image_that_does_not_decode_is_named_in_the_console(self):
        page = self.tmp / "damaged.html"
        png = base64.b64encode(b"\x89PNG\r\n\x1a\nnot a png").decode()
        page.write_text(
            '<!DOCTYPE html><html><body><img alt="the PR figure" src="data:image/png;base64,%s">'
            % png + self._script())
        dom, console = browse(page, self.tmp)
        self.assertTrue(any("image not decoded: the PR figure" in line for line in console),
                        console)
        self.assertIn('data-images-loaded="0/1"', dom)

    def _script(self):
        # The checking script of a real report (the last script of the page), taken from a
        # report openable_evaluate writes.
        m = self.tmp / "m.npy"
        np.save(m, np.random.default_rng(1).random((20, 20)).astype(np.float32))
        out = self.tmp / "r.html"
        support.run("openable_evaluate", ["--matrix", m, "--gt-type", "aligned",
                                          "--reference-frames", "10", "--report", out,
                                          "--quiet"], self.tmp)
        text = out.read_text()
        return text[text.rindex("<script>"):]


class EvaluateReport(support.TempDirTestCase):
    """openable_evaluate --report: frames from --images/--images-2, or named only."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.matrix = cls.tmp / "m.npy"
        support.run_sample(cls.tmp, "Image_sequences=10", "Npy_name=%s" % cls.matrix, "Png_name=")

    def evaluate(self, *extra):
        return subprocess.run(
            [support.program("openable_evaluate"), "--matrix", str(self.matrix),
             "--reference-frames", "300", "--gt-type", "aligned", "--quiet"]
            + [str(e) for e in extra], cwd=str(self.tmp), stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True)

    def test_frames_shown_with_images(self):
        out = self.tmp / "with.html"
        done = self.evaluate("--report", out, "--images", support.SAMPLE / "summer",
                             "--images-2", support.SAMPLE / "winter",
                             "--set", "Report_examples=3")
        self.assertEqual(done.returncode, 0, done.stderr)
        page = Page(out.read_text())
        self.assertEqual(page.sections, SECTIONS)
        frames = [i for i in page.images if i.get("class") == "frame"]
        self.assertEqual(len(frames), 3 * 3 * 2)  # 3 wrong matches and 3 misses, 3 frames each
        self.assertIn("images-", frames[0]["alt"])

    def test_frames_named_without_images(self):
        out = self.tmp / "without.html"
        done = self.evaluate("--report", out)
        self.assertEqual(done.returncode, 0, done.stderr)
        text = out.read_text()
        self.assertIn("Frames are named, not shown", text)
        self.assertEqual(len([i for i in Page(text).images if i.get("class") == "frame"]), 0)

    def test_frames_that_do_not_fit_the_matrix_are_refused(self):
        out = self.tmp / "bad.html"
        done = self.evaluate("--report", out, "--images", support.SAMPLE / "summer")
        self.assertEqual(done.returncode, 1)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
        self.assertIn("Images_path (--images): 300 frames", done.stderr)
        self.assertIn("600 x 600", done.stderr)
        self.assertFalse(out.exists())

    def test_matrices_of_different_sizes_cannot_share_the_frames(self):
        other = self.tmp / "other.npy"
        np.save(other, np.random.default_rng(2).random((40, 20)).astype(np.float32))
        # A pairs ground truth both fit (an aligned one needs as many queries as references).
        pairs = self.tmp / "pairs.csv"
        pairs.write_text("0,0\n5,5\n")
        out = self.tmp / "two.html"
        done = self.evaluate("--matrix", other, "--gt-type", "pairs", "--ground-truth", pairs,
                             "--report", out, "--images", support.SAMPLE / "summer",
                             "--images-2", support.SAMPLE / "winter")
        self.assertEqual(done.returncode, 1)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
        self.assertIn("matrices of different sizes", done.stderr)
        self.assertIn("600 x 600", done.stderr)
        self.assertIn("40 x 20", done.stderr)
        self.assertFalse(out.exists())

    def test_report_without_ground_truth_is_written(self):
        # One sequence, no Ground_truth_type: the page of the run's answers, which says so.
        out = self.tmp / "none.html"
        done = subprocess.run([support.program("Test_OpenABLE"), "--quiet",
                               "--set", "Images_path=%s" % (support.SAMPLE / "summer"),
                               "--set", "Match_threshold=0.2", "--set", "Exclusion=50",
                               "--set", "Report_name=%s" % out], cwd=str(self.tmp),
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        page = Page(out.read_text())
        self.assertEqual(page.sections,
                         ["settings", "operating-point", "matrix", "explore", "accepted"])
        settings = dict((r[0], r[1]) for r in page.tables["settings-table"][1:])
        self.assertEqual(settings["exclusion"], "50 frames")
        self.assertIn("No ground truth", out.read_text())


if __name__ == "__main__":
    unittest.main()
