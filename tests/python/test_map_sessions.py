"""Maps of several sessions through openable_map and the Python API, on the bundled Nordland
sample (summer and winter of one route): the best matches a query prints equal a brute-force
search over the rows written here with numpy (Hamming distances, sequences cut at each
traversal's start and scaled to L terms); merges and appends refuse what does not fit with
one line, exit status 1 and the map unchanged."""
import json
import subprocess
import unittest

import numpy as np

import openable
from support import SAMPLE, TempDirTestCase, program, run

L = 3


def hamming(a, b):
    """Bits differing between every row of `a` and every row of `b` (uint8 rows)."""
    x = np.bitwise_xor(a[:, None, :], b[None, :, :])
    return np.unpackbits(x, axis=2).sum(axis=2).astype(np.float64)


def sequence_best(queries, references, length):
    """For each query i: (best reference j, its distance) of the sequence distance with as many
    terms as both traversals hold (min(L, i + 1, j + 1)) scaled to L terms, ties to the lower j."""
    d = hamming(queries, references)
    best = []
    for i in range(len(queries)):
        scores = []
        for j in range(len(references)):
            terms = min(length, i + 1, j + 1)
            total = sum(d[i - k, j - k] for k in range(terms))
            scores.append(np.float32(total * length / terms))
        j = int(np.argmin(scores))
        best.append((j, float(scores[j])))
    return best


def images(season):
    return sorted((SAMPLE / season).glob("*.png"))


def run_failing(args, cwd):
    done = subprocess.run([program("openable_map")] + [str(a) for a in args], cwd=str(cwd),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return done


class OpenableMapTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.map = cls.tmp / "route.map"
        run("openable_map", ["add", cls.map, "--images", SAMPLE / "summer", "--session", "summer",
                             "--time", "2026-07-01T10:00:00Z", "--quiet"], cls.tmp)
        run("openable_map", ["add", cls.map, "--images", SAMPLE / "winter", "--session", "winter",
                             "--quiet"], cls.tmp)
        reader = lambda season: [openable.read_image(p) for p in images(season)]
        cls.summer = openable.describe_images(reader("summer"))
        cls.winter = openable.describe_images(reader("winter"))

    def test_info_lists_the_sessions(self):
        info = json.loads(run("openable_map", ["info", self.map, "--json"], self.tmp).stdout)
        self.assertEqual(info["format_version"], 3)
        self.assertEqual(info["checksums"], "ok")
        self.assertEqual([(s["name"], s["first"], s["frames"]) for s in info["sessions"]],
                         [("summer", 0, len(self.summer)),
                          ("winter", len(self.summer), len(self.winter))])
        self.assertEqual(info["sessions"][0]["time"], "2026-07-01T10:00:00Z")
        self.assertEqual(info["settings"]["frame_size"], "64x32")

    def test_a_search_key_set_at_query_keeps_the_others_of_the_map(self):
        # A map saved with the ratio score over +-7 frames: a query that sets only Match_score
        # keeps the map's window (the two keys are one struct, set key by key).
        saved = self.tmp / "window7.map"
        run("openable_map", ["add", saved, "--images", SAMPLE / "summer", "--session", "summer",
                             "--set", "Match_score=ratio", "--set", "Match_score_window=7",
                             "--quiet"], self.tmp)
        for given, expected in (("Match_score=ratio", "ratio score (window +-7)"),
                                ("Match_score_window=4", "ratio score (window +-4)")):
            done = run("openable_map", ["query", saved, "--images", SAMPLE / "winter", "--set",
                                        given], self.tmp)
            out = done.stdout + done.stderr  # the search line is on stderr
            search = [line for line in out.splitlines() if line.startswith("search:")]
            self.assertEqual(len(search), 1, out)
            self.assertIn(expected, search[0])

    def test_query_equals_brute_force(self):
        done = run("openable_map", ["query", self.map, "--images", SAMPLE / "winter",
                                    "--session", "summer", "--set", "Image_sequences=%d" % L,
                                    "--json"], self.tmp)
        queries = json.loads(done.stdout)["queries"]
        expected = sequence_best(self.winter, self.summer, L)
        self.assertEqual(len(queries), len(expected))
        for q, name, (j, distance) in zip(queries, images("winter"), expected):
            self.assertEqual(q["query"], name.name)
            self.assertEqual(q["session"], "summer")
            self.assertEqual((q["frame"], q["distance"]), (j, distance), name.name)
            # The score of the distance: the mean fraction of differing bits.
            self.assertAlmostEqual(q["score"], distance / (256 * L), places=6)
        # Every session (L = 1): a winter query finds itself in the winter session, or the
        # first frame of the same row (a few dark frames are identical).
        done = run("openable_map", ["query", self.map, "--images", SAMPLE / "winter", "--json"],
                   self.tmp)
        queries = json.loads(done.stdout)["queries"]
        for i, q in enumerate(queries):
            first = next(j for j in range(len(self.winter))
                         if np.array_equal(self.winter[j], self.winter[i]))
            self.assertEqual((q["session"], q["frame"], q["distance"]), ("winter", first, 0))

    def test_python_query_and_merge(self):
        d = openable.OnlineDetector.open(self.map, sequence_length=L)
        self.assertEqual([s["name"] for s in d.sessions], ["summer", "winter"])
        self.assertEqual(d.session_of(len(self.summer) + 4), ("winter", 4))
        results = d.query(self.winter, sessions="summer")
        for r, (j, distance) in zip(results, sequence_best(self.winter, self.summer, L)):
            self.assertEqual((r[0]["session"], r[0]["frame"], r[0]["distance"]),
                             ("summer", j, distance))
        # Two maps of one season each, merged: the rows and sessions of the map built in one go.
        summer_map, winter_map = self.tmp / "s.map", self.tmp / "w.map"
        for path, season, rows in ((summer_map, "summer", self.summer),
                                   (winter_map, "winter", self.winter)):
            one = openable.OnlineDetector()
            one.start_session(season)
            one.add_images_to_map([openable.read_image(p) for p in images(season)])
            np.testing.assert_array_equal(one.descriptors, rows)
            one.save_map(path)
        merged = self.tmp / "merged.map"
        self.assertEqual(openable.merge_maps(summer_map, winter_map, merged),
                         len(self.summer) + len(self.winter))
        m = openable.OnlineDetector.open(merged)
        np.testing.assert_array_equal(m.descriptors, np.vstack([self.summer, self.winter]))
        self.assertEqual([(s["name"], s["frames"]) for s in m.sessions],
                         [("summer", len(self.summer)), ("winter", len(self.winter))])
        with self.assertRaisesRegex(openable.InputError, "both maps have a session named"):
            openable.merge_maps(summer_map, summer_map, self.tmp / "never.map")
        self.assertFalse((self.tmp / "never.map").exists())

    def test_misfits_are_refused_and_the_map_kept(self):
        before = self.map.read_bytes()
        done = run_failing(["add", self.map, "--images", SAMPLE / "winter", "--session", "winter"],
                           self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn('already has a session named "winter"', done.stderr)
        self.assertEqual(done.stderr.count("\n"), 1, done.stderr)
        done = run_failing(["add", self.map, "--images", SAMPLE / "winter", "--session", "w2",
                            "--set", "Ldb_bits=512"], self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("the map describes frames with LDB 64 256", done.stderr)
        # Frames of another size: PGM files of 128 x 64 written here.
        big = self.tmp / "big"
        big.mkdir(exist_ok=True)
        for i in range(3):
            with open(big / ("f%d.pgm" % i), "wb") as f:
                f.write(b"P5\n128 64\n255\n" + bytes((i * 7 + k) % 256 for k in range(128 * 64)))
        done = run_failing(["add", self.map, "--images", big, "--session", "big"], self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("f0.pgm\" is 128x64; the map's frames are 64x32", done.stderr)
        self.assertEqual(self.map.read_bytes(), before)
        # A damaged map: the query prints nothing and names the file.
        damaged = self.tmp / "damaged.map"
        data = bytearray(before)
        data[len(data) // 2] ^= 0x40
        damaged.write_bytes(bytes(data))
        done = run_failing(["query", damaged, "--images", SAMPLE / "winter", "--json"], self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertEqual(done.stdout, "")
        self.assertIn("damaged.map: the map is damaged", done.stderr)
        # A truncated map, and one of a newer format version.
        (self.tmp / "short.map").write_bytes(before[:len(before) // 3])
        done = run_failing(["info", self.tmp / "short.map"], self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("short.map: the map is truncated", done.stderr)
        newer = bytearray(before)
        newer[16] = 9
        (self.tmp / "newer.map").write_bytes(bytes(newer))
        done = run_failing(["info", self.tmp / "newer.map"], self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("written by a newer OpenABLE", done.stderr)
        # Merging maps of other description settings.
        other = self.tmp / "other.map"
        run("openable_map", ["add", other, "--images", SAMPLE / "summer", "--session", "o",
                             "--set", "Ldb_bits=512", "--quiet"], self.tmp)
        done = run_failing(["merge", self.map, other, "-o", self.tmp / "m.map"], self.tmp)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("other.map: the map was made with ldb_bits = 512", done.stderr)
        self.assertFalse((self.tmp / "m.map").exists())
        # A bad command line: status 2.
        self.assertEqual(run_failing(["add", self.map], self.tmp).returncode, 2)


if __name__ == "__main__":
    unittest.main()
