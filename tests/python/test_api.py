"""The module's surface: version, docstrings on everything, the error types and messages."""
import inspect
import re
import unittest

import numpy as np

import openable
import openable.snaps
from support import DATASETS_DIR, SOURCE_DIR, TempDirTestCase, require, run

GARDENS_POINT = DATASETS_DIR / "gardens_point"


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

    def test_approximate_engines_are_the_programs(self):
        # The names come from the engine registry: the Python property accepts each (any case),
        # its docstring names each, and a bad name lists them as Test_OpenABLE's key does.
        names = openable.approximate_engines()
        self.assertEqual(names[-1], "auto")
        self.assertEqual(openable.OnlineOptions().engine, "auto")
        doc = openable.OnlineOptions.engine.__doc__
        for name in names:
            self.assertEqual(openable.OnlineOptions(engine=name.upper()).engine, name)
            self.assertRegex(doc, r"\b%s[ ,]" % re.escape(name))
        with self.assertRaises(openable.InputError) as caught:
            openable.OnlineOptions(engine="annoy")
        listed = ", ".join(names[:-1]) + " or " + names[-1]
        self.assertEqual(str(caught.exception),
                         'engine: "annoy" is not valid; expected %s' % listed)
        done = run_expect_failure("Test_OpenABLE", ["--set", "Approximate_engine=annoy"], self.tmp)
        self.assertIn('Approximate_engine: "annoy" is not valid; expected %s\n' % listed,
                      done.stderr)


def run_expect_failure(name, args, cwd):
    import subprocess
    from support import program
    done = subprocess.run([program(name), "--quiet"] + args, cwd=str(cwd),
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert done.returncode == 1, (done.returncode, done.stderr)
    return done


if __name__ == "__main__":
    unittest.main()


class NotebookHabitsTest(TempDirTestCase):
    """What a notebook user expects: pathlib paths, RGB images on request, readable results."""

    def setUp(self):
        from pathlib import Path
        self.folder = Path(SOURCE_DIR) / "examples" / "data" / "nordland_sample" / "summer"
        self.paths = sorted(p for p in self.folder.iterdir() if p.suffix == ".png")

    def colour_frames(self):
        """Real colour frames (the Nordland sample is grey in three equal channels)."""
        folder = GARDENS_POINT / "day_left"
        require(folder)
        return [folder / ("Image%03d.jpg" % i) for i in range(4)]

    def test_pathlib_paths(self):
        listed = openable.list_images(self.folder)
        self.assertEqual(listed, [str(p) for p in self.paths])  # names of equal width: sorted
        np.testing.assert_array_equal(openable.read_image(self.paths[0]),
                                      openable.read_image(str(self.paths[0])))

    def test_rgb_order_on_request(self):
        paths = self.colour_frames()
        bgr = openable.read_image(paths[0])
        rgb = openable.read_image(paths[0], color_order="rgb")
        self.assertEqual(bgr.shape[2], 3)
        self.assertFalse(np.array_equal(bgr, rgb))  # a real colour frame: channels differ
        np.testing.assert_array_equal(rgb, bgr[..., ::-1])
        rgb_before = rgb.copy()
        # The same grey image and descriptor rows whichever order the image is given in.
        np.testing.assert_array_equal(openable.to_gray8(rgb, color_order="rgb"),
                                      openable.to_gray8(bgr))
        # Luma by hand (OpenCV's weights on R, G, B) from the RGB array.
        luma = 0.299 * rgb[..., 0] + 0.587 * rgb[..., 1] + 0.114 * rgb[..., 2]
        self.assertLessEqual(np.abs(openable.to_gray8(rgb, color_order="rgb").astype(float) -
                                    luma * 255).max(), 1.0)
        np.testing.assert_array_equal(openable.describe(rgb, color_order="rgb"),
                                      openable.describe(bgr))
        stack = [openable.read_image(p, color_order="rgb") for p in paths]
        np.testing.assert_array_equal(
            openable.describe_images(stack, color_order="rgb"),
            openable.describe_images([openable.read_image(p) for p in paths]))
        a, b = openable.OnlineDetector(), openable.OnlineDetector()
        for p in paths[:3]:
            a.add_frame(openable.read_image(p, color_order="rgb"), color_order="rgb")
            b.add_frame(openable.read_image(p))
        np.testing.assert_array_equal(a.descriptors, b.descriptors)
        np.testing.assert_array_equal(rgb, rgb_before)  # the caller's array is not reordered
        # Grey images have no order: unchanged.
        grey = openable.to_gray8(bgr)
        np.testing.assert_array_equal(openable.describe(grey, color_order="rgb"),
                                      openable.describe(grey))
        with self.assertRaises(ValueError) as caught:
            openable.read_image(paths[0], color_order="hsv")
        self.assertIn("'hsv'", str(caught.exception))
        self.assertEqual(len(str(caught.exception).splitlines()), 1)

    def test_results_print_what_they_hold(self):
        rng = np.random.default_rng(3)
        m = rng.random((30, 30)).astype(np.float32)
        result = openable.evaluate(m, aligned=True, reference_frames=15, tolerance=1)
        text = repr(result)
        self.assertTrue(text.startswith("<openable.EvaluationResult"), text)
        self.assertIn("AUC %.4f" % result.auc, text)
        self.assertIn("<openable.Curve", repr(result.curve))
        detector = openable.OnlineDetector(sequence_length=2)
        self.assertIn("L=2, 0 frames", repr(detector))
        self.assertIn("'sequence_length': 2", repr(detector.options))
        poses = np.tile(np.eye(4), (3, 1, 1))
        self.assertIn("3 poses", repr(openable.snaps.Trajectory(poses)))
        for obj in (result, result.curve, detector, detector.options,
                    openable.snaps.Trajectory(poses)):
            self.assertNotIn(" object at 0x", repr(obj))
