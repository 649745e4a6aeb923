"""The page of a map's query (openable_map query --output PREFIX, no ground truth) opened in
Debian's Chromium, headless, through its DevTools protocol (browser.py): every embedded image
decodes, the frames of the most confident accepted matches are shown side by side, read from
the files the map names, and they are the matches the query's CSV accepted. Skipped when
chromium is not installed."""
import csv
import unittest

import browser
import support

EXAMPLES = 4


@unittest.skipIf(browser.CHROMIUM is None, "chromium is not installed (apt-get install chromium)")
class MapQueryPage(support.TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        preset = support.SOURCE_DIR / "config" / "presets" / "across_conditions.txt"
        path = cls.tmp / "route.map"
        support.run("openable_map", ["add", path, "--images", support.SAMPLE / "summer",
                                     "--session", "summer", "--config", preset, "--quiet"],
                    cls.tmp)
        support.run("openable_map", ["query", path, "--images", support.SAMPLE / "winter",
                                     "--session", "summer", "--output", cls.tmp / "q",
                                     "--set", "Report_examples=%d" % EXAMPLES, "--quiet"],
                    cls.tmp)
        with open(cls.tmp / "q.csv") as f:
            cls.rows = list(csv.DictReader(f))
        cls.browser = browser.Browser(cls.tmp)
        cls.browser.open(cls.tmp / "q.html",
                         ready="document.body.getAttribute('data-explorers') === '1'"
                               " && document.body.getAttribute('data-images-loaded') !== null")

    @classmethod
    def tearDownClass(cls):
        cls.browser.close()
        super().tearDownClass()

    def evaluate(self, expression):
        return self.browser.evaluate(expression)

    def test_every_image_decodes(self):
        done, total = (int(v) for v in
                       self.evaluate("document.body.getAttribute('data-images-loaded')").split("/"))
        self.assertEqual(done, total)
        self.assertGreater(total, 2 * EXAMPLES)

    def test_the_accepted_frames_are_the_querys_most_confident_matches(self):
        shown = self.evaluate(
            "Array.prototype.map.call(document.querySelectorAll('table[data-kind=\"accepted-"
            "confident\"] tr[data-query]'), function (r) { var i = r.querySelectorAll("
            "'img.frame'); return [+r.getAttribute('data-query'), i[0].alt, i[1].alt, "
            "i[0].naturalWidth, i[1].naturalWidth]; })")
        accepted = [(float(r["score"]), i) for i, r in enumerate(self.rows) if r["accepted"] == "1"]
        self.assertGreater(len(accepted), EXAMPLES)
        expected = [i for _, i in sorted(accepted)][:EXAMPLES]
        self.assertEqual([s[0] for s in shown], expected)
        summer = sorted(p.name for p in (support.SAMPLE / "summer").iterdir())
        for query, query_name, reference_name, w0, w1 in shown:
            row = self.rows[query]
            self.assertEqual(query_name, row["query"])
            self.assertEqual(reference_name, summer[int(row["frame"])])
            self.assertGreater(w0, 0)
            self.assertGreater(w1, 0)

    def test_the_page_says_there_is_no_ground_truth(self):
        text = self.evaluate("document.body.innerText")
        self.assertIn("No ground truth", text)
        self.assertIn("openable_map query", text)
        accepted = sum(r["accepted"] == "1" for r in self.rows)
        table = self.evaluate("document.querySelector('#operating-point table, "
                              "#operating-point-table').innerText")
        self.assertIn(str(accepted), table)

    def test_zz_console_stays_silent(self):
        self.evaluate("1")
        self.assertEqual(self.browser.console, [])


if __name__ == "__main__":
    unittest.main()
