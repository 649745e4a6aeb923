"""pip install . (setup.py, pyproject.toml): the package installed into a virtual environment
and into a user site works without the build tree, and pip uninstall removes it.

The installs reuse the build tree CTest runs (OPENABLE_CMAKE_BUILD_DIR; nothing is compiled
again): what is tested is what pip puts where, and that the installed package finds its
programs and run-time modules there. The full build that a fresh clone does is the same CMake
build; its time is in docs/benchmarks.md ("pip install").
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

import support

BUILD_TREE = os.environ.get("OPENABLE_BUILD_TREE", str(support.SOURCE_DIR / "build"))
PACKAGE_FILES = {"__init__.py", "__main__.py", "bin", "modules"}
PROGRAMS = {"Test_OpenABLE", "openable_evaluate", "openable_snaps", "openable_sweep",
            "openable_map"}


def clean_env(**extra):
    """The environment of a user's shell: nothing pointing into the build tree."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "OPENABLE_MODULE_PATH") and not k.startswith("OPENABLE_EXE_")}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    env["PIP_NO_INDEX"] = "1"  # offline: nothing may come from an index
    env.update(extra)
    return env


def check(command, cwd, env, what):
    done = subprocess.run([str(c) for c in command], cwd=str(cwd), env=env, text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if done.returncode != 0:
        raise AssertionError("%s exited with %d:\n%s\n%s"
                             % (what, done.returncode, done.stdout[-3000:], done.stderr[-3000:]))
    return done


def pgm(path, image):
    """A binary PGM written by hand (read back through the run-time module of OpenCV's codecs)."""
    with open(path, "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (image.shape[1], image.shape[0]))
        f.write(image.tobytes())


def probe(python, env, cwd, image_path):
    """Imports openable with `python`, reads a PGM and reports where everything came from."""
    code = r"""
import json, sys, openable
image = openable.read_image(sys.argv[1])
with open("/proc/self/maps") as f:
    modules = sorted({line.split()[-1] for line in f if "libopenable_" in line})
print(json.dumps({"file": openable.__file__, "version": openable.__version__,
                  "image": image.tolist(), "modules": modules}))
"""
    done = check([python, "-c", code, image_path], cwd, env, "import openable")
    return json.loads(done.stdout)


class VirtualEnvironment(support.TempDirTestCase):
    """python3 -m venv --system-site-packages, then pip install --no-build-isolation ."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not (Path(BUILD_TREE) / "python" / "package_files.txt").exists():
            raise unittest.SkipTest("no Python package in the build tree %s" % BUILD_TREE)
        cls.venv = cls.tmp / "venv"
        cls.env = clean_env(OPENABLE_CMAKE_BUILD_DIR=BUILD_TREE)
        check([sys.executable, "-m", "venv", "--system-site-packages", cls.venv], cls.tmp,
              cls.env, "python3 -m venv")
        cls.python = cls.venv / "bin" / "python"
        check([cls.python, "-m", "pip", "install", "--no-build-isolation", support.SOURCE_DIR],
              cls.tmp, cls.env, "pip install --no-build-isolation .")
        cls.site = Path(check([cls.python, "-c", "import sysconfig; print(sysconfig.get_paths()"
                               "['purelib'])"], cls.tmp, cls.env, "sysconfig").stdout.strip())

    def test_package_holds_the_extension_programs_and_modules(self):
        package = self.site / "openable"
        names = {p.name for p in package.iterdir()}
        self.assertTrue(PACKAGE_FILES <= names, names)
        self.assertEqual(len([n for n in names if n.startswith("_openable")
                              and n.endswith(".so")]), 1, names)
        self.assertEqual({p.name for p in (package / "bin").iterdir()}, PROGRAMS)
        for p in (package / "bin").iterdir():
            self.assertTrue(os.access(p, os.X_OK), p)
        self.assertIn("libopenable_codecs.so", {p.name for p in (package / "modules").iterdir()})
        self.assertTrue((self.venv / "bin" / "openable").exists())

    def test_import_uses_the_installed_package_and_its_modules(self):
        image = (np.arange(6 * 5, dtype=np.uint8) * 8).reshape(6, 5)
        pgm(self.tmp / "probe.pgm", image)
        # From a folder outside the repository, so that nothing of the build tree is on the path.
        report = probe(self.python, self.env, self.tmp, self.tmp / "probe.pgm")
        self.assertEqual(Path(report["file"]).resolve(),
                         (self.site / "openable" / "__init__.py").resolve())
        with open(support.SOURCE_DIR / "CMakeLists.txt") as f:
            self.assertIn("project(OpenABLE VERSION %s " % report["version"], f.read())
        np.testing.assert_allclose(np.array(report["image"]), image / 255.0, atol=1e-7)
        self.assertEqual(report["modules"],
                         [str((self.site / "openable" / "modules" / "libopenable_codecs.so")
                              .resolve())])

    def test_command_line_from_python(self):
        done = check([self.python, "-m", "openable", "--help"], self.tmp, self.env, "--help")
        for command in ("run", "evaluate", "sweep", "snaps"):
            self.assertRegex(done.stdout, r"\n  %s +\S" % command)
        self.assertIn(str(self.site / "openable" / "bin"), done.stdout)
        done = subprocess.run([str(self.python), "-m", "openable", "frob"], env=self.env,
                              text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.assertEqual(done.returncode, 2)
        self.assertEqual(len(done.stderr.splitlines()), 1, done.stderr)
        self.assertIn("'frob'", done.stderr)
        # A run of the bundled sample through python3 -m openable run and through the
        # console script gives the build tree's matrix, byte for byte.
        args = ["--set", "Images_path=%s" % (support.SAMPLE / "summer"),
                "--set", "Images_path_2=%s" % (support.SAMPLE / "winter"),
                "--set", "Image_sequences=5", "--json"]
        matrices = []
        for name, command in (("module", [self.python, "-m", "openable", "run"]),
                              ("script", [self.venv / "bin" / "openable", "run"]),
                              ("build", [support.program("Test_OpenABLE")])):
            out = self.tmp / name
            out.mkdir()
            done = check(command + args + ["--set", "Npy_name=%s" % (out / "m.npy")], out,
                         self.env, "%s run" % name)
            report = json.loads(done.stdout)
            self.assertEqual(report["program"], "Test_OpenABLE")
            matrices.append((out / "m.npy").read_bytes())
        self.assertEqual(matrices[0], matrices[2])
        self.assertEqual(matrices[1], matrices[2])

    def test_tutorial_runs_in_the_environment(self):
        done = subprocess.run([str(self.python), str(support.SOURCE_DIR / "tests" / "python" /
                                                    "run_tutorial.py"),
                               str(support.SOURCE_DIR / "docs" / "python.md")],
                              env=self.env, text=True, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT)
        if done.returncode == 77:
            self.skipTest(done.stdout.strip())
        self.assertEqual(done.returncode, 0, done.stdout[-3000:])
        self.assertIn("blocks ran", done.stdout)


class UserSite(support.TempDirTestCase):
    """pip install --user . into a user base of its own (PYTHONUSERBASE), then pip uninstall."""

    def test_install_use_uninstall(self):
        if not (Path(BUILD_TREE) / "python" / "package_files.txt").exists():
            self.skipTest("no Python package in the build tree %s" % BUILD_TREE)
        base = self.tmp / "userbase"
        # Debian's Python refuses pip outside a virtual environment (PEP 668) unless told
        # --break-system-packages; with --user, only PYTHONUSERBASE is written.
        env = clean_env(OPENABLE_CMAKE_BUILD_DIR=BUILD_TREE, PYTHONUSERBASE=str(base))
        pip = [sys.executable, "-m", "pip"]
        check(pip + ["install", "--user", "--break-system-packages", "--no-build-isolation",
                     support.SOURCE_DIR], self.tmp, env, "pip install --user")
        image = np.full((4, 4), 51, np.uint8)
        pgm(self.tmp / "probe.pgm", image)
        report = probe(sys.executable, env, self.tmp, self.tmp / "probe.pgm")
        self.assertTrue(Path(report["file"]).resolve().is_relative_to(base.resolve()), report)
        self.assertTrue(report["modules"] and report["modules"][0].startswith(str(base.resolve())))
        self.assertTrue((base / "bin" / "openable").exists())

        check(pip + ["uninstall", "-y", "--break-system-packages", "openable"], self.tmp, env,
              "pip uninstall")
        left = [str(p) for p in base.rglob("*") if p.is_file()]
        self.assertEqual(left, [])
        done = subprocess.run([sys.executable, "-c", "import openable"], cwd=str(self.tmp),
                              env=env, stderr=subprocess.PIPE, text=True)
        # An openable installed system-wide (cmake --install) would still import: only the
        # user site must be gone.
        if done.returncode == 0:
            where = check([sys.executable, "-c", "import openable; print(openable.__file__)"],
                          self.tmp, env, "import").stdout
            self.assertNotIn(str(base), where)


DEBIAN_PYTHON = "/usr/bin/python3"
ONE_LINE_HINT = "/usr/bin/python3 -m venv --system-site-packages"


def foreign_python(env):
    """The first python3 on PATH that is not Debian's (pyenv, conda, a build of one's own), as
    (interpreter, base prefix), or None."""
    for folder in env.get("PATH", "").split(os.pathsep):
        candidate = os.path.join(folder, "python3")
        if not folder or not os.access(candidate, os.X_OK):
            continue
        done = subprocess.run([candidate, "-c", "import sys; print(sys.executable); "
                               "print(sys.base_prefix)"], env=env, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
        if done.returncode != 0:
            continue
        executable, base = done.stdout.split("\n")[:2]
        if base != "/usr":
            return executable, base
        return None  # the first python3 on PATH is Debian's
    return None


class NotDebiansPython(support.TempDirTestCase):
    """docs/python.md's install run by a python3 that is not Debian's (pyenv, conda): it must
    work, or stop before building with one line naming Debian's Python; the build tree's module
    imported by it must work, or fail with a one-line hint.

    When PATH has no such Python (a CI machine), a venv of Debian's Python made without its
    site packages stands in: it has pip and setuptools but neither NumPy nor wheel, as a fresh
    pyenv Python.
    """

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not (Path(BUILD_TREE) / "python" / "package_files.txt").exists():
            raise unittest.SkipTest("no Python package in the build tree %s" % BUILD_TREE)
        cls.env = clean_env(OPENABLE_CMAKE_BUILD_DIR=BUILD_TREE)
        found = foreign_python(cls.env)
        if found:
            cls.python, base = found
            cls.what = "%s (base %s)" % (cls.python, base)
            # What a user of that Python does with the documented commands: a venv of it.
            cls.venv = cls.tmp / "venv"
            check([cls.python, "-m", "venv", "--system-site-packages", cls.venv], cls.tmp,
                  cls.env, "venv of " + cls.python)
        else:
            cls.venv = cls.tmp / "stand_in"
            cls.what = "stand-in venv of %s without its site packages" % DEBIAN_PYTHON
            check([DEBIAN_PYTHON, "-m", "venv", cls.venv], cls.tmp, cls.env, "stand-in venv")
        print("\nNot Debian's Python: %s" % cls.what, file=sys.stderr)
        cls.venv_python = cls.venv / "bin" / "python"

    def test_pip_install_works_or_says_in_one_line_what_to_use(self):
        done = subprocess.run([str(self.venv_python), "-m", "pip", "install",
                               "--no-build-isolation", str(support.SOURCE_DIR)],
                              cwd=str(self.tmp), env=self.env, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        output = done.stdout
        if done.returncode == 0:
            # This Python had NumPy and wheel: the installed package must import and work.
            image = np.full((3, 4), 102, np.uint8)
            pgm(self.tmp / "probe.pgm", image)
            report = probe(self.venv_python, self.env, self.tmp, self.tmp / "probe.pgm")
            np.testing.assert_allclose(np.array(report["image"]), image / 255.0, atol=1e-7)
            return
        lines = [line.strip() for line in output.splitlines() if "setup.py: " in line]
        self.assertEqual(len(lines), 1, output[-3000:])
        self.assertIn(ONE_LINE_HINT, lines[0])
        self.assertIn(str(self.venv_python.parent), lines[0])  # names the Python it ran with
        self.assertNotIn("invalid command", output)
        self.assertNotIn("Traceback", output)
        # Nothing was installed.
        done = subprocess.run([str(self.venv_python), "-c", "import openable"], cwd=str(self.tmp),
                              env=self.env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.assertNotEqual(done.returncode, 0)

    def test_build_tree_module_imports_or_gives_a_one_line_hint(self):
        env = dict(self.env, PYTHONPATH=str(Path(BUILD_TREE) / "python"))
        pgm(self.tmp / "tree.pgm", np.full((2, 5), 153, np.uint8))
        # Importing is not enough: reading an image returns a NumPy array.
        done = subprocess.run([str(self.venv_python), "-c",
                               "import sys, openable; print(openable.read_image(sys.argv[1])"
                               ".shape)", str(self.tmp / "tree.pgm")],
                              cwd=str(self.tmp), env=env, text=True, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE)
        if done.returncode == 0:
            self.assertEqual(done.stdout.strip(), "(2, 5)")
            return
        last = done.stderr.strip().splitlines()[-1]
        self.assertTrue(last.startswith("ImportError: openable"), done.stderr)
        self.assertIn(ONE_LINE_HINT, last)
        built_for = (Path(BUILD_TREE) / "python" / "openable" / "_build_tree.py").read_text()
        named = re.search(r"built for (\S+?)[;,]", last)
        self.assertTrue(named, last)
        self.assertIn('PYTHON_EXECUTABLE = "%s"' % named.group(1), built_for)
        # The hint replaces the error: no chained traceback of the failed import.
        self.assertNotIn("During handling", done.stderr)

    def test_debians_python_installs_it(self):
        """The documented command with Debian's Python works (the other classes check the
        installed package in detail)."""
        if not os.access(DEBIAN_PYTHON, os.X_OK):
            self.skipTest("no %s" % DEBIAN_PYTHON)
        venv = self.tmp / "debian_venv"
        check([DEBIAN_PYTHON, "-m", "venv", "--system-site-packages", venv], self.tmp, self.env,
              "python3 -m venv")
        check([venv / "bin" / "pip", "install", "--no-build-isolation", support.SOURCE_DIR],
              self.tmp, self.env, "pip install --no-build-isolation .")
        image = np.full((2, 3), 204, np.uint8)
        pgm(self.tmp / "debian.pgm", image)
        report = probe(venv / "bin" / "python", self.env, self.tmp, self.tmp / "debian.pgm")
        self.assertTrue(Path(report["file"]).resolve().is_relative_to(venv.resolve()), report)
        np.testing.assert_allclose(np.array(report["image"]), image / 255.0, atol=1e-7)


if __name__ == "__main__":
    unittest.main()
