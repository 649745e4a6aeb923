"""A whole Test_OpenABLE run on a network's rows (Image_descriptor ONNX) against NumPy: the 16
frames PyTorch described in tests/data/onnx/make_models.py, the pairwise L2 distances of
PyTorch's vectors divided by their largest (Eq. 5), as the run's matrix must hold them."""
import unittest

import numpy as np

from support import SAMPLE, SOURCE_DIR, TempDirTestCase, run, settings

ONNX = SOURCE_DIR / "tests" / "data" / "onnx"
CONFIG = SOURCE_DIR / "config" / "Config.txt"


def numpy_matrix(rows):
    """M' of single frames: L2 distances of the rows, divided by the largest."""
    rows = rows.astype(np.float64)
    d = np.sqrt(np.maximum(((rows[:, None, :] - rows[None, :, :]) ** 2).sum(axis=2), 0.0))
    return d / d.max()


class OnnxRunTest(TempDirTestCase):
    def test_the_run_matrix_is_numpys_on_pytorchs_vectors(self):
        # The frames PyTorch described, in a folder of their own (their names sort as listed).
        frames = self.tmp / "frames"
        frames.mkdir()
        for line in (ONNX / "frames.txt").read_text().split():
            (frames / line).symlink_to(SAMPLE / "summer" / line)
        for name in ("netvlad", "gem", "projection"):
            expected = numpy_matrix(np.load(ONNX / ("%s_outputs.npy" % name)))
            out = self.tmp / ("%s.npy" % name)
            run("Test_OpenABLE",
                [CONFIG, "--quiet"] + settings(
                    "Images_path=%s" % frames, "Images_path_2=",
                    "Image_descriptor=ONNX", "Model_path=%s" % (ONNX / ("%s.onnx" % name)),
                    "Model_input_size=64x32", "Model_normalize=0", "Image_sequences=1",
                    "Exclusion=1", "Ground_truth_type=none", "Npy_name=%s" % out, "Png_name=",
                    "Txt_name=", "Evaluation_name=", "Report_name="), self.tmp)
            m = np.load(out)
            self.assertEqual(m.shape, (16, 16))
            # The run takes L2 distances as sqrt(|a|^2 + |b|^2 - 2 a.b) in float32 (OpenBLAS),
            # which loses about 1e-7 |a|^2 / d of a distance d: up to 2e-5 of the largest here
            # (the projection's rows are not normalised, its distances small against its
            # norms). A wrong row, order or normalisation is off by 1e-2 or more.
            self.assertLess(np.abs(m - expected).max(), 1e-4, name)

    def test_a_bad_model_is_one_line_and_nothing_written(self):
        bad = self.tmp / "bad.onnx"
        bad.write_bytes(b"not a network")
        import subprocess
        from support import program
        done = subprocess.run(
            [program("Test_OpenABLE"), str(CONFIG), "--quiet"] + settings(
                "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=",
                "Image_descriptor=ONNX", "Model_path=%s" % bad, "Model_input_size=64x32",
                "Npy_name=%s" % (self.tmp / "none.npy")),
            cwd=str(self.tmp), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
        self.assertIn("not an ONNX network", done.stderr)
        self.assertFalse((self.tmp / "none.npy").exists())

    def test_a_configured_model_joins_the_auto_modes_candidates(self):
        done = run("Test_OpenABLE",
                   [SOURCE_DIR / "config" / "presets" / "auto.txt", "--json"] + settings(
                       "Images_path=%s" % (SAMPLE / "summer"),
                       "Images_path_2=%s" % (SAMPLE / "winter"),
                       "Model_path=%s" % (ONNX / "gem.onnx"), "Model_input_size=64x32",
                       "Auto_candidates=Image_descriptor=HOG Image_sequences=10", "Npy_name=",
                       "Png_name=", "Txt_name=", "Evaluation_name=", "Report_name="), self.tmp)
        import json
        auto = json.loads(done.stdout)["auto"]
        settings_judged = [c["settings"] for c in auto["candidates"]]
        for length in (10, 20, 40):
            self.assertIn("Image_descriptor=ONNX Image_sequences=%d" % length, settings_judged)
        self.assertIn("Image_descriptor=HOG Image_sequences=10", settings_judged)

    def test_python_the_online_detector_and_maps_run_a_network(self):
        import json
        import shutil
        import subprocess
        import openable
        from support import program
        names = (ONNX / "frames.txt").read_text().split()
        images = [openable.read_image(str(SAMPLE / "summer" / n)) for n in names]
        expected = np.load(ONNX / "gem_outputs.npy")
        rows = openable.describe_images(images, descriptor="ONNX",
                                        model_path=str(ONNX / "gem.onnx"),
                                        model_input_size="64x32", model_batch=5)
        self.assertEqual(rows.dtype, np.float32)
        self.assertLess(np.abs(rows - expected).max(), 1e-5)
        one = openable.describe(images[3], descriptor="ONNX", model_path=str(ONNX / "gem.onnx"),
                                model_input_size="64x32")
        self.assertLess(np.abs(one - expected[3]).max(), 1e-5)
        # The online detector: frames added one by one, each its network row.
        detector = openable.OnlineDetector(descriptor="ONNX", model_path=str(ONNX / "gem.onnx"),
                                           model_input_size="64x32", sequence_length=1)
        for image in images:
            detector.add_frame(image)
        self.assertEqual(detector.size, 16)
        # Its map keeps the network's settings and the digest of its weights: opened with no
        # option, it describes queries with the same network (its nearest frame is itself).
        detector.save_map(str(self.tmp / "net.map"))
        reopened = openable.OnlineDetector.open(str(self.tmp / "net.map"), sequence_length=1)
        self.assertLess(np.abs(reopened.descriptors - expected).max(), 1e-5)
        for i, result in enumerate(reopened.query_images(images)):
            self.assertEqual(result[0]["frame"], i)
        # openable_map add and query with a network, from another working folder.
        work = self.tmp / "work"
        work.mkdir()
        frames = self.tmp / "map_frames"
        frames.mkdir()
        for n in names:
            shutil.copy(SAMPLE / "summer" / n, frames / n)
        model = self.tmp / "model.onnx"
        shutil.copy(ONNX / "gem.onnx", model)

        def map_tool(*args):
            return subprocess.run([program("openable_map")] + [str(a) for a in args],
                                  cwd=str(work), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  text=True)
        done = map_tool("add", "m.map", "--images", frames, "--session", "s",
                        "--set", "Image_descriptor=ONNX", "--set", "Model_path=../model.onnx",
                        "--set", "Model_input_size=64x32", "--set", "Image_sequences=1")
        self.assertEqual(done.returncode, 0, done.stderr)
        info = json.loads(map_tool("info", "m.map", "--json").stdout)
        self.assertEqual(info["settings"]["model_path"], str(model))
        self.assertEqual(info["settings"]["model_input_size"], "64x32")
        done = map_tool("query", "m.map", "--images", frames, "--json")
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual([q["frame"] for q in json.loads(done.stdout)["queries"]],
                         list(range(16)))
        # Other weights under the map's model path: refused in one line naming both digests.
        shutil.copy(ONNX / "projection.onnx", model)
        done = map_tool("query", "m.map", "--images", frames)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)
        self.assertIn("the map was made with the network", done.stderr)
        # The map's network moved: Model_path names the copy, whose weights are checked.
        done = map_tool("query", "m.map", "--images", frames, "--set",
                        "Model_path=%s" % (ONNX / "gem.onnx"), "--json")
        self.assertEqual(done.returncode, 0, done.stderr)

if __name__ == "__main__":
    unittest.main()
