"""openable_map as several processes and signals meet it: two appends to one map at once both
land (the map's write lock), an interrupt at any moment of add, tune or merge leaves the old
map or the new one, whole, says which in one line and leaves no temporary; --time is an ISO
8601 UTC time; adding large frames keeps memory bounded by a batch of frames, not by their
number. The maps are read back with the Python module (sessions, sizes) after each case."""
import json
import os
import signal
import subprocess
import sys
import time
import unittest

import numpy as np

import openable
from support import NORDLAND, SAMPLE, TempDirTestCase, program, run


def start(args, cwd):
    return subprocess.Popen([program("openable_map")] + [str(a) for a in args], cwd=str(cwd),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def sessions(path):
    return [s["name"] for s in openable.OnlineDetector.open(str(path)).sessions]


def temporaries(folder):
    return [p.name for p in folder.iterdir() if ".tmp-" in p.name]


class ConcurrentWriters(TempDirTestCase):
    def test_two_appends_at_once_both_land(self):
        for trial in range(5):
            path = self.tmp / ("route%d.map" % trial)
            run("openable_map", ["add", path, "--images", SAMPLE / "summer", "--session", "base",
                                 "--quiet"], self.tmp)
            a = start(["add", path, "--images", SAMPLE / "summer", "--session", "a"], self.tmp)
            b = start(["add", path, "--images", SAMPLE / "winter", "--session", "b"], self.tmp)
            out_a, err_a = a.communicate()
            out_b, err_b = b.communicate()
            self.assertEqual((a.returncode, b.returncode), (0, 0), err_a + err_b)
            self.assertEqual(sorted(sessions(path)), ["a", "b", "base"], "trial %d" % trial)
            self.assertEqual(openable.OnlineDetector.open(str(path)).size, 900)
            self.assertEqual(temporaries(self.tmp), [])


class Interrupts(TempDirTestCase):
    """SIGINT and SIGTERM at moments spread over a whole add of the shared Nordland summer (the
    bundled sample when absent) to a map of one session."""

    def setUp(self):
        self.images = NORDLAND / "summer" if NORDLAND.exists() else SAMPLE / "summer"
        self.base = self.tmp / "base.map"
        if not self.base.exists():
            run("openable_map", ["add", self.base, "--images", SAMPLE / "winter", "--session",
                                 "first", "--quiet"], self.tmp)
        timings = []
        for t in range(3):  # the median of three, against a moment of load
            t0 = time.monotonic()
            run("openable_map", ["add", self.tmp / ("timing%d.map" % t), "--images", self.images,
                                 "--session", "s", "--quiet"], self.tmp)
            timings.append(time.monotonic() - t0)
        self.duration = sorted(timings)[1]

    def test_the_old_map_or_the_new_one_and_one_line(self):
        outcomes = set()
        seen = []  # (moment, status) of each trial, for the message
        for k in range(36):  # twelve moments; again while no signal has met a running add
            if k >= 12 and "unchanged" in outcomes:
                break
            path = self.tmp / ("m%d.map" % k)
            path.write_bytes(self.base.read_bytes())
            p = start(["add", path, "--images", self.images, "--session", "second"], self.tmp)
            time.sleep(self.duration * (k % 12 + 0.5) / 12)
            p.send_signal(signal.SIGTERM if k % 2 else signal.SIGINT)
            _, err = p.communicate()
            seen.append((k, p.returncode))
            names = sessions(path)   # the map reads back whole (checksums, sessions)
            self.assertIn(names, (["first"], ["first", "second"]), err)
            self.assertEqual(temporaries(self.tmp), [], err)
            if p.returncode == 0:
                outcomes.add("finished")
                self.assertEqual(names, ["first", "second"])
                continue
            if p.returncode < 0:  # the signal came before the program began: nothing done
                self.assertEqual(names, ["first"])
                continue
            self.assertIn(p.returncode, (130, 143), err)
            lines = [line for line in err.splitlines() if "interrupted" in line]
            self.assertEqual(len(lines), 1, err)
            said = "unchanged" if "%s unchanged" % path.name in lines[0] else "holds"
            self.assertIn(said, lines[0])
            self.assertEqual(names, ["first"] if said == "unchanged" else ["first", "second"])
            outcomes.add(said)
        self.assertIn("unchanged", outcomes,
                      "no signal met a running add (%.3f s): %s" % (self.duration, seen))


class MergeInterrupts(TempDirTestCase):
    """SIGINT and SIGTERM at moments spread over a merge of two maps into a third."""

    def test_no_output_or_the_whole_merge_and_one_line(self):
        images = NORDLAND / "summer" if NORDLAND.exists() else SAMPLE / "summer"
        a, b = self.tmp / "a.map", self.tmp / "b.map"
        # HOG rows (a 13 MB map of Nordland): a merge long enough to be interrupted in its midst.
        for path, name in ((a, "a"), (b, "b")):
            run("openable_map", ["add", path, "--images", images, "--session", name, "--quiet",
                                 "--set", "Image_descriptor=HOG"], self.tmp)
        timings = []
        for t in range(3):  # the median of three, against a moment of load
            t0 = time.monotonic()
            run("openable_map", ["merge", a, b, "-o", self.tmp / ("timing%d.map" % t),
                                 "--quiet"], self.tmp)
            timings.append(time.monotonic() - t0)
        duration = sorted(timings)[1]
        outcomes = set()
        seen = []  # (moment, status, output written) of each trial, for the messages
        for k in range(36):  # twelve moments; again while no signal has met a running merge
            if k >= 12 and outcomes & {"not written", "written"}:
                break
            out = self.tmp / ("c%d.map" % k)
            p = start(["merge", a, b, "-o", out], self.tmp)
            time.sleep(duration * (k % 12 + 0.5) / 12)
            p.send_signal(signal.SIGTERM if k % 2 else signal.SIGINT)
            _, err = p.communicate()
            seen.append((k, p.returncode, out.exists()))
            self.assertEqual(temporaries(self.tmp), [], err)
            if out.exists():  # whole, with both sessions
                self.assertEqual(sessions(out), ["a", "b"], err)
            if p.returncode == 0:
                self.assertTrue(out.exists())
                outcomes.add("finished")
                continue
            if p.returncode < 0:  # the signal came before the program began: nothing done
                self.assertFalse(out.exists())
                continue
            self.assertIn(p.returncode, (130, 143), err)
            lines = [line for line in err.splitlines() if "interrupted" in line]
            self.assertEqual(len(lines), 1, err)
            outcomes.add("written" if out.exists() else "not written")
            if out.exists():
                self.assertIn("%s written" % out.name, lines[0])
        self.assertTrue(outcomes & {"not written", "written"},
                        "no signal met a running merge (%.3f s): %s" % (duration, seen))


class Times(TempDirTestCase):
    def test_time_is_iso_8601_utc(self):
        path = self.tmp / "t.map"
        for bad in ("yesterday", "2026-02-30T10:00:00Z", "2026-11-29 10:00:00Z",
                    "2026-11-29T10:00:00", "1" * 100000):
            done = subprocess.run([program("openable_map"), "add", str(path), "--images",
                                   str(SAMPLE / "summer"), "--session", "s", "--time", bad],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            self.assertEqual(done.returncode, 1, bad[:40])
            self.assertEqual(done.stderr.count("\n"), 1)
            self.assertIn("--time", done.stderr)
            self.assertIn("YYYY-MM-DDTHH:MM:SSZ", done.stderr)
            self.assertFalse(path.exists())
        run("openable_map", ["add", path, "--images", SAMPLE / "summer", "--session", "s",
                             "--time", "2024-02-29T23:59:59.5Z", "--quiet"], self.tmp)
        self.assertEqual(openable.OnlineDetector.open(str(path)).sessions[0]["time"],
                         "2024-02-29T23:59:59.5Z")


class Memory(TempDirTestCase):
    def test_large_frames_are_added_a_batch_at_a_time(self):
        folder = self.tmp / "large"
        folder.mkdir()
        # A black 3840 x 2160 colour PNG, written once (zlib) and copied: 24 frames of 25 MB.
        import zlib, struct
        width, height = 3840, 2160
        raw = b"".join(b"\x00" + bytes(3 * width) for _ in range(height))
        def chunk(kind, data):
            return (struct.pack(">I", len(data)) + kind + data +
                    struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
        png = (b"\x89PNG\r\n\x1a\n" +
               chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
               chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
        for i in range(24):
            (folder / ("f%02d.png" % i)).write_bytes(png)
        # The peak of the program alone, measured by a process of its own (RUSAGE_CHILDREN of
        # this one would hold the earlier tests' programs too).
        probe = ("import resource, subprocess, sys; "
                 "done = subprocess.run(sys.argv[1:], capture_output=True); "
                 "print(done.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
        done = subprocess.run([sys.executable, "-c", probe, program("openable_map"), "add",
                               str(self.tmp / "large.map"), "--images", str(folder),
                               "--session", "s", "--quiet"],
                              stdout=subprocess.PIPE, text=True, check=True)
        status, peak_kb = (int(v) for v in done.stdout.split())
        self.assertEqual(status, 0)
        self.assertEqual(openable.OnlineDetector.open(str(self.tmp / "large.map")).size, 24)
        # 24 frames held at once would be 600 MB as 8-bit colour and more as floats.
        self.assertLess(peak_kb / 1024, 500, "peak RSS %.0f MB" % (peak_kb / 1024))


if __name__ == "__main__":
    unittest.main()
