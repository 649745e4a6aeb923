"""The module's surface: version, docstrings on everything, the error types and messages."""
import inspect
import re
import unittest

import numpy as np

import openable
import openable.snaps
from support import SOURCE_DIR, TempDirTestCase, run


def public(obj):
    return [(n, getattr(obj, n)) for n in dir(obj) if not n.startswith("_")]


class ApiTest(unittest.TestCase):
    def test_version_is_the_project_version(self):
        cmake = (SOURCE_DIR / "CMakeLists.txt").read_text()
        version = re.search(r"project\(OpenABLE VERSION ([0-9.]+)", cmake).group(1)
        self.assertEqual(openable.__version__, version)

    def test_every_function_class_and_member_has_a_docstring(self):
        missing = []
        for module in (openable, openable.snaps):
            self.assertGreater(len(module.__doc__ or ""), 100, module.__name__)
            for name, obj in public(module):
                if inspect.ismodule(obj):
                    continue
                doc = (obj.__doc__ or "").strip()
                if len(doc) < 20:
                    missing.append("%s.%s" % (module.__name__, name))
                if inspect.isclass(obj) and not issubclass(obj, BaseException):
                    for member_name, member in public(obj):
                        member_doc = (getattr(member, "__doc__", None) or "").strip()
                        if isinstance(member, property) or callable(member):
                            if len(member_doc) < 10:
                                missing.append("%s.%s.%s" % (module.__name__, name, member_name))
        self.assertEqual(missing, [], "members without a docstring")

    def test_function_docstrings_start_with_their_signature_and_describe_arguments(self):
        for module in (openable, openable.snaps):
            for name, obj in public(module):
                # Functions are the pybind11 builtins, wrapped for one-line TypeErrors.
                if inspect.isbuiltin(getattr(obj, "__wrapped__", obj)) and callable(obj):
                    doc = obj.__doc__
                    self.assertTrue(doc.startswith(name + "("), "%s: %r" % (name, doc[:60]))
                    if "Args:" not in doc:  # short functions describe arguments in prose
                        self.assertGreater(len(doc), 120, name)

    def test_arguments_of_the_wrong_type_are_one_line(self):
        image = np.zeros((32, 64), np.uint8)
        for call in (lambda: openable.describe(image, patch_size=10**20),
                     lambda: openable.describe(image, descriptor=3),
                     lambda: openable.OnlineDetector(sequence_length="a"),
                     lambda: openable.OnlineDetector().add_frame(image, 5)):
            with self.assertRaises(TypeError) as caught:
                call()
            message = str(caught.exception)
            self.assertNotIn("\n", message)
            self.assertIn("expected (", message)
            self.assertNotIn("Invoked with", message)
        self.assertTrue(openable.describe.__doc__.startswith("describe("))

    def test_input_error_is_a_value_error(self):
        self.assertTrue(issubclass(openable.InputError, ValueError))
        with self.assertRaises(openable.InputError) as caught:
            openable.read_image("/nonexistent/frame.png")
        message = str(caught.exception)
        self.assertIn('"/nonexistent/frame.png"', message)
        self.assertNotIn("\n", message)

    def test_logic_errors_are_value_errors(self):
        with self.assertRaises(ValueError) as caught:
            openable.sequence_distances(np.ones((3, 3), np.float32), 0)
        self.assertNotIsInstance(caught.exception, openable.InputError)


class SameMessageAsTheProgramsTest(TempDirTestCase):
    def test_trajectory_file_error(self):
        bad = self.tmp / "bad.txt"
        bad.write_text("1 0 0 0 0 1 0 0 0 0 1\n")  # 11 numbers
        with self.assertRaises(openable.InputError) as caught:
            openable.snaps.read_trajectory(str(bad))
        done = run_expect_failure("openable_snaps",
                                  ["--set", "Snaps_trajectory=%s" % bad, "--set",
                                   "Snaps_loops=pairs", "--set", "Snaps_loops_file=x.csv"],
                                  self.tmp)
        self.assertIn(str(caught.exception), done.stderr)
        self.assertEqual(done.stderr.count("\n"), 1, done.stderr)

    def test_unknown_descriptor(self):
        with self.assertRaises(openable.InputError) as caught:
            openable.describe(np.zeros((32, 32), np.uint8), descriptor="SURFACE")
        done = run_expect_failure("Test_OpenABLE",
                                  ["--set", "Image_descriptor=SURFACE", "--set",
                                   "Images_path_2=", "--set",
                                   "Images_path=%s" % (SOURCE_DIR / "examples" / "data" /
                                                       "nordland_sample" / "summer")],
                                  self.tmp)
        self.assertEqual(done.stderr, "Test_OpenABLE: error: %s\n" % caught.exception)


def run_expect_failure(name, args, cwd):
    import subprocess
    from support import program
    done = subprocess.run([program(name), "--quiet"] + args, cwd=str(cwd),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert done.returncode == 1, (done.returncode, done.stderr)
    return done


if __name__ == "__main__":
    unittest.main()
