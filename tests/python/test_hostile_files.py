"""Small ground-truth files that claim much: a GT.npz whose member inflates to 256 MiB and a
VPR-Bench pickle whose rows all name one memoised range of 2,000,000 numbers. openable_evaluate
must refuse each in one line before it allocates what the file claims: its peak resident memory
is measured by a process of its own (the readers once took 1.33 GB and 331 MB on these files)."""
import pickle
import subprocess
import sys
import unittest
import zipfile

import numpy as np

from support import TempDirTestCase, program

# A run's own memory (about 25 MB) and room to spare, far below what the files claim.
PEAK_MB = 100


def peak_of(args, cwd):
    """(status, stderr, peak RSS in MB) of one program run."""
    probe = ("import resource, subprocess, sys; "
             "done = subprocess.run(sys.argv[1:], capture_output=True, text=True); "
             "sys.stderr.write(done.stderr); "
             "print(done.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    done = subprocess.run([sys.executable, "-c", probe] + args, cwd=cwd,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, check=True)
    status, peak_kb = (int(v) for v in done.stdout.split())
    return status, done.stderr, peak_kb / 1024


def npy_header(shape, descr):
    """A .npy version 1.0 header for `shape` and `descr`, padded as NumPy pads it."""
    text = "{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, repr(tuple(shape)))
    text += " " * ((64 - (10 + len(text) + 1) % 64) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text.encode()


class BombsTest(TempDirTestCase):
    def test_npz_member_that_inflates_to_256_mib(self):
        matrix = self.tmp / "m.npy"
        np.save(matrix, np.random.default_rng(1).random((10, 10), dtype=np.float32))
        bomb = self.tmp / "GT.npz"
        side = 16384  # 16384 x 16384 bools: 256 MiB once inflated
        with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as archive:
            with archive.open("GThard.npy", "w", force_zip64=True) as member:
                member.write(npy_header((side, side), "|b1"))
                zeros = bytes(1 << 20)
                for _ in range(side * side // len(zeros)):
                    member.write(zeros)
        self.assertLess(bomb.stat().st_size, 1 << 20)
        status, err, peak = peak_of(
            [program("openable_evaluate"), "--matrix", str(matrix), "--layout", "query_reference",
             "--gt-type", "vpr_tutorial", "--ground-truth", str(bomb)], self.tmp)
        self.assertEqual(status, 1, err)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertIn('member "GThard.npy" holds %d bytes once inflated' % (side * side + 128),
                      err)
        self.assertIn("expected at most", err)
        self.assertLess(peak, PEAK_MB, "peak RSS %.0f MB" % peak)

    def test_vpr_bench_rows_naming_one_memoised_range(self):
        rows = 49
        matrix = self.tmp / "m.npy"
        np.save(matrix, np.random.default_rng(2).random((rows, rows), dtype=np.float32))
        shared = range(2_000_000)  # pickled once, named from every row through the memo
        truth = np.empty((rows, 2), dtype=object)
        for q in range(rows):
            truth[q, 0] = q
            truth[q, 1] = shared
        bomb = self.tmp / "ground_truth_new.npy"
        np.save(bomb, truth, allow_pickle=True)
        self.assertLess(bomb.stat().st_size, 4096)
        # The pickle names the range once and refers to it 48 more times.
        self.assertEqual(pickle.dumps(truth).count(b"range"), 1)
        status, err, peak = peak_of(
            [program("openable_evaluate"), "--matrix", str(matrix), "--layout", "query_reference",
             "--gt-type", "vpr_bench", "--ground-truth", str(bomb)], self.tmp)
        self.assertEqual(status, 1, err)
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertIn("the range objects make 2000000 numbers in all; expected at most", err)
        self.assertLess(peak, PEAK_MB, "peak RSS %.0f MB" % peak)


if __name__ == "__main__":
    unittest.main()
