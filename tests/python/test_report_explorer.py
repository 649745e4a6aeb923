"""The explorer of the HTML report (section "explore", docs/output_formats.md) driven in a real
browser: Debian's Chromium, headless, through its DevTools protocol (browser.py). A click on a
cell shows that cell's two frames, their names and the distance the run's .npy holds there; the
threshold slider shows the accepted count, precision and recall computed here with NumPy from
the same .npy; the queries are listed by score; the console stays silent. Every expected value
comes from the run's own files, not from the page. Skipped when chromium is not installed.
"""
import base64
import re
import unittest

import numpy as np

import browser
import openable
import support

TOLERANCE = 2  # the default Tolerance, frames


@unittest.skipIf(browser.CHROMIUM is None, "chromium is not installed (apt-get install chromium)")
class Explorer(support.TempDirTestCase):
    """The sample (summer references, winter queries), aligned ground truth, distance score."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.report = cls.tmp / "report.html"
        support.run_sample(cls.tmp, "Ground_truth_type=aligned", "Image_sequences=5",
                           "Match_score=distance", "Npy_name=%s" % (cls.tmp / "m.npy"),
                           "Png_name=", "Evaluation_name=%s" % (cls.tmp / "eval"),
                           "Report_name=%s" % cls.report, "Report_examples=2")
        matrix = np.load(cls.tmp / "m.npy")
        cls.block = matrix[300:, :300]  # winter queries x summer references
        cls.queries = sorted(p.name for p in (support.SAMPLE / "winter").iterdir())
        cls.references = sorted(p.name for p in (support.SAMPLE / "summer").iterdir())
        # Each query's best match and its distance (the score), by NumPy.
        finite = np.isfinite(cls.block)
        cls.answered = finite.any(axis=1)
        filled = np.where(finite, cls.block, np.inf)
        cls.best = np.argmin(filled, axis=1)
        cls.best_distance = filled[np.arange(300), cls.best]
        cls.correct = cls.answered & (np.abs(cls.best - np.arange(300)) <= TOLERANCE)
        cls.browser = browser.Browser(cls.tmp)
        cls.browser.open(cls.report, ready="document.body.getAttribute('data-explorers') === '1'")

    @classmethod
    def tearDownClass(cls):
        cls.browser.close()
        super().tearDownClass()

    def text(self, selector):
        return self.browser.evaluate(
            "document.querySelector('#explorer-0 %s').textContent" % selector)

    def click_cell(self, query, reference):
        b = self.browser
        rect = b.evaluate("(function () { var e = document.querySelector('#explorer-0 .ex-image');"
                          " e.scrollIntoView({block: 'center'}); var r = e.getBoundingClientRect();"
                          " return [r.left, r.top, r.width, r.height]; })()")
        left, top, width, height = rect
        b.click(left + (reference + 0.5) * width / 300, top + (query + 0.5) * height / 300)
        self.assertEqual(b.evaluate("document.getElementById('explorer-0').getAttribute("
                                    "'data-cell')"), "%d,%d" % (query, reference))

    def test_clicking_a_best_match_shows_its_frames_and_exact_distance(self):
        # The most confident wrong match, else the most confident answer.
        wrong = np.flatnonzero(self.answered & ~self.correct)
        pool = wrong if len(wrong) else np.flatnonzero(self.answered)
        query = int(pool[np.argmin(self.best_distance[pool])])
        reference = int(self.best[query])
        self.click_cell(query, reference)
        self.assertEqual(self.text(".ex-cell-query"), "query %d \u00b7 %s" % (query, self.queries[query]))
        self.assertEqual(self.text(".ex-cell-reference"),
                         "reference %d \u00b7 %s" % (reference, self.references[reference]))
        distance = float(re.match(r"distance ([0-9.e+-]+) \(exact\)",
                                  self.text(".ex-cell-distance")).group(1))
        self.assertAlmostEqual(distance, float(self.block[query, reference]), delta=1e-5)
        score = self.text(".ex-cell-score")
        self.assertIn("the query's best match", score)
        self.assertIn("wrong" if len(wrong) else "right", score)
        self.assertAlmostEqual(float(re.search(r"distance score ([0-9.e+-]+)", score).group(1)),
                               float(self.best_distance[query]), delta=1e-5)
        # The two thumbnails are the frames themselves (64 x 32, JPEG: close, not equal).
        shots = self.browser.evaluate(
            "Array.prototype.map.call(document.querySelectorAll('#explorer-0 .ex-cell-frames "
            "canvas'), function (c) { return c.toDataURL('image/png'); })")
        self.assertEqual(len(shots), 2)
        for shot, folder, name, other in (
                (shots[0], "winter", self.queries[query], self.queries[(query + 150) % 300]),
                (shots[1], "summer", self.references[reference],
                 self.references[(reference + 150) % 300])):
            png = self.tmp / "shot.png"
            png.write_bytes(base64.b64decode(shot.split(",", 1)[1]))
            drawn = openable.read_image(png)[..., :3]
            frame = openable.read_image(support.SAMPLE / folder / name)
            elsewhere = openable.read_image(support.SAMPLE / folder / other)
            self.assertEqual(drawn.shape, frame.shape)
            error = np.abs(drawn - frame).mean()
            self.assertLess(error, 0.04, name)
            self.assertLess(error, np.abs(drawn - elsewhere).mean(), name)

    def test_clicking_any_cell_shows_its_8_bit_distance(self):
        query = 120
        reference = int((self.best[query] + 97) % 300)
        self.assertTrue(np.isfinite(self.block[query, reference]))
        self.click_cell(query, reference)
        self.assertEqual(self.text(".ex-cell-reference"),
                         "reference %d \u00b7 %s" % (reference, self.references[reference]))
        shown = float(re.match(r"distance \u2248 ([0-9.]+) \(8-bit",
                               self.text(".ex-cell-distance")).group(1))
        # Quantised to 1/254, shown to 3 decimals.
        self.assertLessEqual(abs(shown - float(self.block[query, reference])), 0.5 / 254 + 0.0005)
        self.assertIn("not the query's best match (reference %d" % self.best[query],
                      self.text(".ex-cell-score"))

    def set_threshold(self, t):
        self.browser.evaluate("(function () { var s = document.querySelector('#explorer-0 "
                              ".ex-threshold'); s.value = '%r'; s.dispatchEvent(new Event('input'));"
                              " })()" % t)

    def test_the_slider_counts_the_accepted_matches(self):
        scores = np.unique(self.best_distance[self.answered])
        positives = int(self.answered.sum())  # aligned: every query has a true place
        for fraction in (0.1, 0.6):
            k = int(fraction * (len(scores) - 1))
            t = float(scores[k] + scores[k + 1]) / 2  # between two scores: no tie at the edge
            self.set_threshold(t)
            accepted = self.answered & (self.best_distance <= t)
            right = int((accepted & self.correct).sum())
            self.assertEqual(int(self.text(".ex-accepted")), int(accepted.sum()), t)
            self.assertEqual(int(self.text(".ex-correct")), right, t)
            self.assertAlmostEqual(float(self.text(".ex-precision")), right / accepted.sum(),
                                   delta=5e-5)
            self.assertAlmostEqual(float(self.text(".ex-recall")), right / positives, delta=5e-5)
            # The run's own curve (eval_per_query.csv) agrees at that threshold.
            curve = np.loadtxt(self.tmp / "eval_per_query.csv", delimiter=",", skiprows=1, ndmin=2)
            point = curve[curve[:, 0] <= t][-1]
            self.assertEqual(int(point[4] + point[5]), int(accepted.sum()))
            # Accepted best matches are drawn over the matrix: green right, red wrong.
            shot = self.browser.evaluate("document.querySelector('#explorer-0 .ex-overlay')"
                                         ".toDataURL('image/png')")
            png = self.tmp / "overlay.png"
            png.write_bytes(base64.b64decode(shot.split(",", 1)[1]))
            drawn = np.round(openable.read_image(png, color_order="rgb") * 255).astype(int)
            counts = [int(np.all(drawn[..., :3] == colour, axis=-1).sum())
                      for colour in ((0, 200, 0), (224, 0, 0))]
            self.assertEqual(counts[0] > 0, right > 0)
            self.assertEqual(counts[1] > 0, int(accepted.sum()) > right)

    def test_queries_are_listed_by_score(self):
        self.browser.evaluate("(function () { var s = document.querySelector('#explorer-0 "
                              ".ex-order'); s.value = 'confident';"
                              " s.dispatchEvent(new Event('change')); })()")
        listed = self.browser.evaluate(
            "Array.prototype.map.call(document.querySelectorAll('#explorer-0 .ex-queries tbody "
            "tr'), function (r) { return +r.getAttribute('data-query'); })")
        order = np.argsort(np.where(self.answered, self.best_distance, np.inf), kind="stable")
        self.assertEqual(listed[:10], [int(q) for q in order[:10]])
        first = self.browser.evaluate("document.querySelector('#explorer-0 .ex-queries tbody tr')"
                                      ".textContent")
        self.assertIn(self.references[self.best[order[0]]], first)
        self.assertIn("right" if self.correct[order[0]] else "wrong", first)

    def test_zz_console_stays_silent(self):
        # Last (zz): after the clicks and the slider of the other tests.
        self.browser.evaluate("1")
        self.assertEqual(self.browser.console, [])


if __name__ == "__main__":
    unittest.main()
