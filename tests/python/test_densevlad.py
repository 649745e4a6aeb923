"""DenseVLAD in a run: its vocabulary is learnt from the frames of Images_path alone (the
reference's distances among themselves do not depend on the second traversal), the descriptor
cache keys rows by that vocabulary, and the online detector and describe_images refuse it in
one line (they would learn another vocabulary at each call)."""
import json
import unittest

import numpy as np

import openable
from support import SAMPLE, SOURCE_DIR, TempDirTestCase, run, settings

CONFIG = SOURCE_DIR / "config" / "Config.txt"


class DenseVladRunTest(TempDirTestCase):
    def run_against(self, second, name, *pairs):
        """The raw single-frame distances (the matrix times its Eq. 5 divisor) of a DenseVLAD run
        of the sample's summer traversal against `second`, and the run's JSON."""
        done = run("Test_OpenABLE", [CONFIG, "--quiet", "--json"] + settings(
            "Images_path=%s" % (SAMPLE / "summer"), "Images_path_2=%s" % second,
            "Image_descriptor=DenseVLAD", "Png_name=", "Txt_name=", "Evaluation_name=",
            "Report_name=", "Ground_truth_type=", "Image_sequences=1", "Npy_name=%s.npy" % name,
            *pairs), self.tmp)
        report = json.loads(done.stdout)
        return np.load(self.tmp / ("%s.npy" % name)) * report["max_distance"], report

    def test_the_vocabulary_is_learnt_from_the_reference_alone(self):
        # The second traversal: the winter frames, or only the first 100 of them.
        part = self.tmp / "winter_part"
        part.mkdir()
        for p in sorted((SAMPLE / "winter").iterdir())[:100]:
            (part / p.name).symlink_to(p)
        whole, report = self.run_against(SAMPLE / "winter", "whole")
        partial, _ = self.run_against(part, "partial")
        self.assertIn("DENSEVLAD: learnt from 40 frames spread over Images_path (no ground truth)",
                      report["notes"])
        self.assertEqual(report["descriptors"][0]["name"], "DENSEVLAD")
        self.assertEqual(whole.shape, (600, 600))
        # Summer against summer: the same distances whatever the second traversal.
        np.testing.assert_allclose(whole[:300, :300], partial[:300, :300], rtol=1e-5, atol=1e-5)
        # Rows of unit length: distances between 0 and 2.
        self.assertLessEqual(np.nanmax(whole[np.isfinite(whole)]), 2.0 + 1e-5)

    def test_the_cache_keeps_the_rows_of_one_vocabulary(self):
        first, _ = self.run_against(SAMPLE / "winter", "first", "Descriptor_cache=cache")
        again, _ = self.run_against(SAMPLE / "winter", "again", "Descriptor_cache=cache")
        np.testing.assert_array_equal(first, again)

        def cached(reference, query):
            """What a run with `reference` as Images_path says of the cache."""
            return run("Test_OpenABLE", [CONFIG, "--quiet"] + settings(
                "Images_path=%s" % (SAMPLE / reference), "Images_path_2=%s" % (SAMPLE / query),
                "Image_descriptor=DenseVLAD", "Png_name=", "Txt_name=", "Evaluation_name=",
                "Report_name=", "Ground_truth_type=", "Npy_name=", "Descriptor_cache=cache"),
                self.tmp).stdout
        self.assertIn("600 of 600 frames from the cache", cached("summer", "winter"))
        # Another reference, another vocabulary: none of its rows come from this cache.
        self.assertIn("0 of 600 frames from the cache", cached("winter", "summer"))

    def test_describe_images_and_the_detector_refuse_it_in_one_line(self):
        image = openable.read_image(str(sorted((SAMPLE / "summer").iterdir())[0]))
        with self.assertRaises(openable.InputError) as caught:
            openable.describe_images([image, image], descriptor="DenseVLAD")
        self.assertIn("learns its vocabulary from a reference traversal", str(caught.exception))
        self.assertEqual(len(str(caught.exception).splitlines()), 1)
        with self.assertRaises(openable.InputError):
            openable.OnlineDetector(descriptor="DenseVLAD")


if __name__ == "__main__":
    unittest.main()
