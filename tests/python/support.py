"""Helpers of the Python tests: where the data and the programs are, temporary folders.

The real datasets are ../shared/datasets beside the repository (as tests/test_support.h says for
the C++ tests); tests that need them skip with a message when they are absent. The programs are
those of the build that CTest runs (environment set in tests/python/CMakeLists.txt), else
build/examples/ of the repository.
"""
import json
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

import numpy as np

SOURCE_DIR = Path(__file__).resolve().parents[2]
DATASETS_DIR = SOURCE_DIR.parent / "shared" / "datasets"
KITTI00 = DATASETS_DIR / "kitti00_first1700"
KITTI_TRAJECTORIES = DATASETS_DIR / "kitti_trajectories"
NORDLAND = DATASETS_DIR / "nordland_trimmed"
SAMPLE = SOURCE_DIR / "examples" / "data" / "nordland_sample"


def program(name):
    """Path of a command-line program of the build (Test_OpenABLE, openable_snaps, ...)."""
    env = "OPENABLE_EXE_" + name.upper()
    if os.environ.get(env):
        return os.environ[env]
    return str(SOURCE_DIR / "build" / "examples" / name)


def require(path):
    """Skips the calling test (or class, in setUpClass) when `path` does not exist."""
    if not Path(path).exists():
        raise unittest.SkipTest("dataset absent: %s" % path)


def run(name, args, cwd):
    """Runs a program of the build in `cwd`; fails with its stderr when it does not succeed."""
    done = subprocess.run([program(name)] + [str(a) for a in args], cwd=str(cwd),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise AssertionError("%s exited with %d:\n%s" % (name, done.returncode, done.stderr))
    return done


def settings(*pairs):
    """The arguments that set each of `pairs` ("Key=value"): --set before each."""
    return [arg for pair in pairs for arg in ("--set", pair)]


def run_sample(cwd, *pairs, first=()):
    """Runs Test_OpenABLE quietly in `cwd` on the bundled sample (summer references, winter
    queries) with each of `pairs` ("Key=value") set, after the arguments `first` (a preset)."""
    return run("Test_OpenABLE",
               list(first) + ["--quiet"] + settings("Images_path=%s" % (SAMPLE / "summer"),
                                                    "Images_path_2=%s" % (SAMPLE / "winter"),
                                                    *pairs), cwd)


class TempDirTestCase(unittest.TestCase):
    """A test case with a fresh temporary folder per class (self.tmp), removed afterwards
    unless OPENABLE_KEEP_TEST_FILES is set."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="openable_py_"))

    @classmethod
    def tearDownClass(cls):
        if not os.environ.get("OPENABLE_KEEP_TEST_FILES"):
            shutil.rmtree(cls.tmp, ignore_errors=True)


def read_json(path):
    with open(path) as f:
        return json.load(f)


def kitti_poses(path):
    """KITTI poses read with NumPy alone: (N, 3, 4)."""
    return np.loadtxt(path).reshape(-1, 3, 4)
