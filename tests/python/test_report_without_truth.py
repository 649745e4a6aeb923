"""The HTML report of a run without ground truth (Report_name, no Ground_truth_type) opened in
Debian's Chromium, headless, through its DevTools protocol (browser.py): every embedded image
decodes, the frames of the most confident accepted matches are shown side by side, the explorer
shows a cell's frames and distance and counts what the threshold slider accepts, and nothing on
the page is called right or wrong or given a precision or recall. The expected values come from
the run's .npy (NumPy) and its matches file, not from the page. Skipped when chromium is not
installed.
"""
import base64
import re
import unittest

import numpy as np

import browser
import openable
import support

WINDOW = 10  # Match_score_window of the across-conditions preset
THRESHOLD = 0.9  # its Match_threshold
EXAMPLES = 3  # Report_examples set below


@unittest.skipIf(browser.CHROMIUM is None, "chromium is not installed (apt-get install chromium)")
class ReportWithoutTruth(support.TempDirTestCase):
    """The across-conditions preset on the sample (summer references, winter queries), with no
    ground truth: ratio score, Match_threshold 0.9, Match_consistency 1."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.report = cls.tmp / "report.html"
        preset = support.SOURCE_DIR / "config" / "presets" / "across_conditions.txt"
        support.run_sample(cls.tmp, "Npy_name=%s" % (cls.tmp / "m.npy"), "Png_name=",
                           "Evaluation_name=", "Matches_name=%s" % (cls.tmp / "matches.csv"),
                           "Report_name=%s" % cls.report, "Report_examples=%d" % EXAMPLES,
                           first=[preset])
        block = np.load(cls.tmp / "m.npy")[300:, :300]  # winter queries x summer references
        cls.block = block
        filled = np.where(np.isfinite(block), block, np.inf)
        cls.answered = np.isfinite(block).any(axis=1)
        cls.best = np.argmin(filled, axis=1)
        cls.distance = filled[np.arange(300), cls.best]
        # The ratio score: the best distance over the smallest more than WINDOW columns away.
        columns = np.arange(300)
        cls.ratio = np.ones(300)
        for q in range(300):
            rivals = filled[q, np.abs(columns - cls.best[q]) > WINDOW]
            rival = rivals.min() if rivals.size else np.inf
            if np.isfinite(rival) and rival > 0:
                cls.ratio[q] = cls.distance[q] / rival
        cls.within = cls.answered & (cls.ratio.astype(np.float32) <= np.float32(THRESHOLD))
        # The run's matches: the rank-1 records the matches file marks confirmed.
        records = np.genfromtxt(cls.tmp / "matches.csv", delimiter=",", names=True, dtype=None)
        first = records[records["rank"] == 1]
        cls.file_accepted = np.zeros(300, bool)
        cls.file_accepted[first["query"]] = first["accepted"] == 1
        cls.confirmed = np.zeros(300, bool)
        cls.confirmed[first["query"]] = first["confirmed"] == 1
        cls.queries = sorted(p.name for p in (support.SAMPLE / "winter").iterdir())
        cls.references = sorted(p.name for p in (support.SAMPLE / "summer").iterdir())
        cls.browser = browser.Browser(cls.tmp)
        cls.browser.open(cls.report, ready="document.body.getAttribute('data-explorers') === '1'"
                         " && document.body.getAttribute('data-images-loaded') !== null")

    @classmethod
    def tearDownClass(cls):
        cls.browser.close()
        super().tearDownClass()

    def evaluate(self, expression):
        return self.browser.evaluate(expression)

    def text(self, selector):
        return self.evaluate("document.querySelector('#explorer-0 %s').textContent" % selector)

    def test_the_matches_file_accepts_what_numpy_accepts(self):
        self.assertTrue(np.array_equal(self.file_accepted, self.within))
        self.assertTrue(np.all(self.confirmed <= self.within))
        self.assertGreater(self.confirmed.sum(), 50)
        self.assertLess(self.confirmed.sum(), self.within.sum())

    def test_every_image_decodes(self):
        loaded = self.evaluate("document.body.getAttribute('data-images-loaded')")
        done, total = (int(v) for v in loaded.split("/"))
        self.assertEqual(done, total)
        self.assertEqual(total, self.evaluate("document.images.length"))

    def test_accepted_frames_are_shown_side_by_side(self):
        rows = self.evaluate(
            "Array.prototype.map.call(document.querySelectorAll('table[data-kind=\"accepted-"
            "confident\"] tr[data-query]'), function (r) { var i = r.querySelectorAll("
            "'img.frame'); return [+r.getAttribute('data-query'), +r.getAttribute("
            "'data-reference'), i.length, i[0].alt, i[1].alt, i[0].naturalWidth, "
            "i[1].naturalWidth, r.cells[0].textContent]; })")
        order = [int(q) for q in np.flatnonzero(self.confirmed)]
        order.sort(key=lambda q: (np.float32(self.ratio[q]), q))
        self.assertEqual([r[0] for r in rows], order[:EXAMPLES])
        for query, reference, images, query_name, reference_name, w0, w1, cell in rows:
            self.assertEqual(reference, self.best[query])
            self.assertEqual(images, 2)
            self.assertEqual(query_name, self.queries[query])
            self.assertEqual(reference_name, self.references[reference])
            self.assertGreater(w0, 0)  # decoded
            self.assertGreater(w1, 0)
            shown = float(re.search(r"distance ([0-9.]+)", cell).group(1))
            self.assertAlmostEqual(shown, float(self.distance[query]), delta=5e-5)
        doubtful = self.evaluate(
            "Array.prototype.map.call(document.querySelectorAll('table[data-kind=\"accepted-"
            "doubtful\"] tr[data-query]'), function (r) { return +r.getAttribute('data-query');"
            " })")
        self.assertEqual(doubtful, order[::-1][:EXAMPLES])

    def test_nothing_is_judged(self):
        # The whole page as a reader sees it, but the notice that says there is no ground truth.
        shown = self.evaluate(
            "(function () { var n = document.getElementById('no-truth'); var t = n.innerText;"
            " return [t, document.body.innerText.replace(t, '')]; })()")
        self.assertIn("No ground truth", shown[0])
        self.assertIn("Ground_truth_type", shown[0])
        for word in ("precision", "recall", "right", "wrong"):
            self.assertIsNone(re.search(r"\b%s\b" % word, shown[1], re.IGNORECASE), word)
        self.assertEqual(self.evaluate("document.querySelectorAll('.ex-precision, .ex-recall, "
                                       ".ex-correct, #figures, #misses').length"), 0)

    def test_clicking_a_best_match_shows_its_frames_and_distance(self):
        query = int(np.flatnonzero(self.confirmed)[0])
        reference = int(self.best[query])
        rect = self.evaluate("(function () { var e = document.querySelector('#explorer-0 "
                             ".ex-image'); e.scrollIntoView({block: 'center'}); var r = "
                             "e.getBoundingClientRect(); return [r.left, r.top, r.width, "
                             "r.height]; })()")
        left, top, width, height = rect
        self.browser.click(left + (reference + 0.5) * width / 300,
                           top + (query + 0.5) * height / 300)
        self.assertEqual(self.evaluate("document.getElementById('explorer-0').getAttribute("
                                       "'data-cell')"), "%d,%d" % (query, reference))
        self.assertEqual(self.text(".ex-cell-query"),
                         "query %d \u00b7 %s" % (query, self.queries[query]))
        self.assertEqual(self.text(".ex-cell-reference"),
                         "reference %d \u00b7 %s" % (reference, self.references[reference]))
        distance = float(re.match(r"distance ([0-9.e+-]+) \(exact\)",
                                  self.text(".ex-cell-distance")).group(1))
        self.assertAlmostEqual(distance, float(self.block[query, reference]), delta=1e-5)
        score = self.text(".ex-cell-score")
        self.assertIn("accepted by the run", score)
        self.assertAlmostEqual(float(re.search(r"ratio score ([0-9.e+-]+)", score).group(1)),
                               float(self.ratio[query]), delta=1e-5)
        self.assertEqual(self.evaluate("document.querySelectorAll('#explorer-0 .ex-cell-frames "
                                       "canvas').length"), 2)

    def test_the_slider_counts_the_accepted_matches(self):
        scores = np.unique(self.ratio[self.answered])
        for fraction in (0.2, 0.7):
            k = int(fraction * (len(scores) - 1))
            t = float(scores[k] + scores[k + 1]) / 2
            self.evaluate("(function () { var s = document.querySelector('#explorer-0 "
                          ".ex-threshold'); s.value = '%r'; s.dispatchEvent(new Event('input'));"
                          " })()" % t)
            accepted = int((self.answered & (self.ratio <= t)).sum())
            self.assertEqual(int(self.text(".ex-accepted")), accepted, t)
            # The accepted best matches are drawn over the matrix in one colour (orange).
            shot = self.evaluate("document.querySelector('#explorer-0 .ex-overlay')"
                                 ".toDataURL('image/png')")
            png = self.tmp / "overlay.png"
            png.write_bytes(base64.b64decode(shot.split(",", 1)[1]))
            drawn = np.round(openable.read_image(png, color_order="rgb") * 255).astype(int)
            counts = [int(np.all(drawn[..., :3] == colour, axis=-1).sum())
                      for colour in ((255, 140, 0), (0, 200, 0), (224, 0, 0))]
            self.assertGreater(counts[0], 0)
            self.assertEqual(counts[1:], [0, 0])  # neither green nor red: nothing is judged

    def test_the_queries_are_listed_with_the_runs_verdict(self):
        self.evaluate("(function () { var s = document.querySelector('#explorer-0 .ex-order');"
                      " s.value = 'confident'; s.dispatchEvent(new Event('change')); })()")
        rows = self.evaluate(
            "Array.prototype.map.call(document.querySelectorAll('#explorer-0 .ex-queries tbody "
            "tr'), function (r) { return [+r.getAttribute('data-query'), "
            "r.cells[r.cells.length - 1].textContent]; })")
        order = np.argsort(np.where(self.answered, self.ratio, np.inf), kind="stable")
        self.assertEqual([r[0] for r in rows[:10]], [int(q) for q in order[:10]])
        for query, verdict in rows:
            expected = ("accepted" if self.confirmed[query]
                        else "not confirmed" if self.within[query] else "")
            self.assertEqual(verdict, expected, query)

    def test_zz_console_stays_silent(self):
        # Last (zz): after the clicks and the slider of the other tests.
        self.evaluate("1")
        self.assertEqual(self.browser.console, [])


if __name__ == "__main__":
    unittest.main()
