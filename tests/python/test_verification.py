"""Geometric verification in the online detector from Python: KITTI 00's revisit (frames
1555-1644 coming back over 100-199) fed frame by frame."""
import os
import unittest

import openable

KITTI = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "datasets",
                     "kitti00_first1700", "image_0")
FRAMES = list(range(100, 200)) + list(range(1555, 1645))


@unittest.skipUnless(os.path.isdir(KITTI), "KITTI frames absent")
class OnlineVerification(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.detector = openable.OnlineDetector(exclusion=50, verification=True,
                                               verification_candidates=5)
        cls.results = [cls.detector.add_frame(
            openable.read_image(os.path.join(KITTI, "%06d.png" % f))) for f in FRAMES]

    def test_candidates_carry_the_checks(self):
        verified = 0
        for frame, candidates, timings in self.results:
            self.assertIn("verify_seconds", timings)
            for candidate in candidates:
                self.assertEqual(len(candidate), 6)
                check = candidate[5]
                self.assertEqual(candidate[3], check["verified"])
                if check["geometric"]:
                    self.assertGreaterEqual(check["inliers"], 40)
                    self.assertIn(check["model"], ("fundamental", "homography"))
                else:
                    self.assertFalse(check["verified"])
                verified += check["verified"]
        self.assertGreater(verified, 20)

    def test_verified_loops_show_the_same_street(self):
        # Within 30 m in the ground truth: two frames of a street share their view over that
        # range (tests/e2e/verification_test.cc says why a loop can be farther than 5 m).
        poses = os.path.join(KITTI, "..", "poses", "00_first1700.txt")
        xz = [(float(p[3]), float(p[11])) for p in (line.split() for line in open(poses))]
        for frame, candidates, _ in self.results:
            for candidate in candidates:
                if candidate[5]["verified"]:
                    a, b = xz[FRAMES[frame]], xz[FRAMES[candidate[0]]]
                    self.assertLess(((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2) ** 0.5, 30,
                                    (frame, candidate))

    def test_options_round_trip_and_descriptor_rows_are_refused(self):
        options = openable.OnlineOptions(verification=True, verification_features="sift")
        self.assertEqual(options["verification_features"], "SIFT")
        self.assertTrue(options.to_dict()["verification"])
        with self.assertRaises(openable.InputError):
            self.detector.add_descriptor(self.detector.descriptors[0])


if __name__ == "__main__":
    unittest.main()
