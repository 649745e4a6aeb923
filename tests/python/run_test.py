"""Runs one test module of this folder (CTest's python.* tests): exit status 0 when it passes,
1 when it fails, 77 (CTest's "Skipped") when every one of its tests skipped."""
import sys
import time
import unittest


def main():
    name = sys.argv[1]
    start = time.monotonic()
    suite = unittest.defaultTestLoader.loadTestsFromName(name)
    result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
    print("%s: %.1f s" % (name, time.monotonic() - start))
    if not result.wasSuccessful():
        return 1
    # A class whose setUpClass skipped counts as one skip and runs no test.
    if result.skipped and len(result.skipped) >= result.testsRun:
        return 77
    return 0


if __name__ == "__main__":
    sys.exit(main())
