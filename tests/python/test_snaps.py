"""openable.snaps against openable_snaps on KITTI 00 (SO-DSO keyframes, ground-truth loop
pairs), and the trajectory error against NumPy."""
import math
import unittest

import numpy as np

import openable
from openable import snaps
from support import KITTI_TRAJECTORIES, TempDirTestCase, read_json, require, run


def ate_reference(estimate, truth, align):
    """RMSE and mean of the position error, with an optional rigid alignment (Kabsch), NumPy only."""
    e, t = np.asarray(estimate, float), np.asarray(truth, float)
    if align:
        ce, ct = e.mean(axis=0), t.mean(axis=0)
        u, _, vt = np.linalg.svd((t - ct).T @ (e - ce))
        s = np.eye(3)
        s[2, 2] = np.sign(np.linalg.det(u @ vt))
        r = u @ s @ vt
        e = (e - ce) @ r.T + ct
    d = np.linalg.norm(e - t, axis=1)
    return math.sqrt((d ** 2).mean()), d.mean()


def close(a, b, rel=1e-5):
    return math.isclose(a, b, rel_tol=rel, abs_tol=1e-9)


class KittiCorrectionTest(TempDirTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        require(KITTI_TRAJECTORIES)
        d = KITTI_TRAJECTORIES
        cls.trajectory_file = d / "vo_so_dso" / "seq00" / "poses_history_file.txt"
        cls.truth_file = d / "poses" / "00.txt"
        cls.pairs_file = d / "loop_pairs" / "groundTruth_KITTI00.pairs.csv"
        run("openable_snaps",
            ["--quiet", "--set", "Snaps_trajectory=%s" % cls.trajectory_file,
             "--set", "Snaps_trajectory_format=kitti-id", "--set", "Snaps_world_to_camera=1",
             "--set", "Snaps_ground_truth=%s" % cls.truth_file, "--set", "Snaps_loops=pairs",
             "--set", "Snaps_loops_file=%s" % cls.pairs_file, "--set", "Snaps_drop_outside=1",
             "--set", "Snaps_middle_of_runs=1", "--set", "Snaps_corrector=both",
             "--set", "Snaps_discount_length=300", "--set", "Snaps_pause=20",
             "--set", "Snaps_output_name=out/k00"], cls.tmp)
        cls.report = read_json(cls.tmp / "out" / "k00.json")
        cls.input = snaps.read_trajectory(str(cls.trajectory_file), "kitti-id",
                                          world_to_camera=True)
        cls.truth = snaps.read_trajectory(str(cls.truth_file))
        cls.loops = snaps.loops_from_csv(str(cls.pairs_file), cls.input, drop_outside=True,
                                         middle_of_runs=True)

    def test_trajectories_read(self):
        self.assertEqual(len(self.input), self.report["poses"])
        self.assertEqual(self.input.format, "kitti-id")
        self.assertEqual(self.input.poses.shape, (len(self.input), 4, 4))
        np.testing.assert_array_equal(self.input.poses[:, 3], [[0, 0, 0, 1]] * len(self.input))
        # Camera-to-world after inversion: the file's matrix times ours is the identity.
        first = np.loadtxt(self.trajectory_file, max_rows=1)
        world_to_camera = np.vstack([first[1:].reshape(3, 4), [0, 0, 0, 1]])
        np.testing.assert_allclose(world_to_camera @ self.input.poses[0], np.eye(4), atol=1e-9)

    def test_loops_are_those_of_the_program(self):
        self.assertEqual(len(self.loops), self.report["loops"])
        cli = np.loadtxt(self.tmp / "out" / "k00_loops.csv", delimiter=",", ndmin=2)
        ids = self.input.frame_ids
        mine = np.array([[ids[q], ids[r], s] for q, r, s in self.loops])
        np.testing.assert_allclose(mine, cli)
        closed = snaps.closed_loops(self.loops, pause=20)
        self.assertEqual(len(closed), self.report["loops_closed_by_discounted_update"])

    def test_discounted_update_matches_the_program(self):
        corrected = snaps.correct_discounted(self.input, self.loops, discount_length=300, pause=20)
        cli = snaps.read_trajectory(str(self.tmp / "out" / "k00_discounted.txt"), "kitti-id",
                                    world_to_camera=True)
        np.testing.assert_array_equal(corrected.frame_ids, cli.frame_ids)
        np.testing.assert_allclose(corrected.poses, cli.poses, atol=1e-9)
        # The file written from Python is the program's, byte for byte.
        corrected.save(str(self.tmp / "py_discounted.txt"))
        self.assertEqual((self.tmp / "py_discounted.txt").read_text(),
                         (self.tmp / "out" / "k00_discounted.txt").read_text())
        self.check_errors(corrected, self.report["errors"]["discounted"])

    def test_pose_graph_matches_the_program(self):
        corrected, report = snaps.correct_pose_graph(self.input, self.loops, report=True)
        cli = snaps.read_trajectory(str(self.tmp / "out" / "k00_pose_graph.txt"), "kitti-id",
                                    world_to_camera=True)
        np.testing.assert_allclose(corrected.poses, cli.poses, atol=1e-7)
        graph = self.report["pose_graph"]
        self.assertEqual(report.loop_edges, graph["loop_edges"])
        self.assertEqual(report.iterations, graph["iterations"])
        self.assertTrue(close(report.final_cost, graph["final_cost"]))
        self.check_errors(corrected, self.report["errors"]["pose_graph"])

    def test_input_error_matches_the_program_and_numpy(self):
        self.check_errors(self.input, self.report["errors"]["input"])

    def test_run_is_the_program(self):
        # openable.snaps.run is the library call openable_snaps makes: with the same keys it
        # writes the same files, byte for byte but the times in the JSON.
        settings = {"Snaps_trajectory": self.trajectory_file,
                    "Snaps_trajectory_format": "kitti-id", "Snaps_world_to_camera": True,
                    "Snaps_ground_truth": self.truth_file, "Snaps_loops": "pairs",
                    "Snaps_loops_file": self.pairs_file, "Snaps_drop_outside": 1,
                    "Snaps_middle_of_runs": 1, "Snaps_corrector": "both",
                    "Snaps_discount_length": 300, "Snaps_pause": 20,
                    "Snaps_output_name": self.tmp / "py" / "k00"}
        result = snaps.run(settings=settings, write=True)
        self.assertEqual(len(result.loops), self.report["loops"])
        self.assertEqual(result.input.encode(), self.input.encode())
        for name in ("k00_discounted.txt", "k00_pose_graph.txt", "k00_loops.csv"):
            self.assertEqual((self.tmp / "py" / name).read_bytes(),
                             (self.tmp / "out" / name).read_bytes(), name)
        mine = read_json(self.tmp / "py" / "k00.json")
        del mine["pose_graph"]["seconds"]
        theirs = dict(self.report, pose_graph=dict(self.report["pose_graph"]))
        del theirs["pose_graph"]["seconds"]
        self.assertEqual(mine, theirs)
        unaligned, aligned = result.errors["pose_graph"]
        self.assertTrue(close(aligned.mean, self.report["errors"]["pose_graph"]["aligned"]["mean_m"]))
        self.assertIn("loops: %d pairs from pairs" % len(result.loops), result.report())
        with self.assertRaisesRegex(openable.InputError, "Snaps_loops_file: empty"):
            snaps.run(settings={"Snaps_trajectory": self.trajectory_file, "Snaps_loops": "pairs"})

    def check_errors(self, trajectory, expected):
        association = snaps.associate(trajectory, self.truth)
        np.testing.assert_array_equal(association, trajectory.frame_ids)  # KITTI: id = line
        for align, key in ((False, "unaligned"), (True, "aligned")):
            e = snaps.trajectory_error(trajectory, self.truth, align=align)
            self.assertEqual(e.aligned, align)
            want = expected[key]
            for name in ("rmse", "mean", "median", "max"):
                self.assertTrue(close(getattr(e, name), want[name + "_m"]),
                                "%s %s: %r vs %r" % (key, name, getattr(e, name), want[name + "_m"]))
            rmse, mean = ate_reference(trajectory.positions,
                                       self.truth.positions[association], align)
            self.assertTrue(close(e.rmse, rmse, 1e-9), (e.rmse, rmse))
            self.assertTrue(close(e.mean, mean, 1e-9), (e.mean, mean))


class TrajectoryTest(TempDirTestCase):
    def poses(self, n=5):
        out = np.zeros((n, 3, 4))
        for i in range(n):
            a = 0.3 * i
            out[i, :, :3] = [[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]]
            out[i, :, 3] = [i, 0.5 * i, -i]
        return out

    def test_round_trips_in_every_format(self):
        p = self.poses()
        for fmt, kwargs in (("kitti", {}), ("kitti-id", {"frame_ids": [3, 4, 8, 9, 20]}),
                            ("tum", {"timestamps": [0.0, 0.1, 0.2, 0.3, 0.4]})):
            for w2c in (False, True):
                with self.subTest(format=fmt, world_to_camera=w2c):
                    t = snaps.Trajectory(p, format=fmt, world_to_camera=w2c, **kwargs)
                    path = self.tmp / ("t_%s_%d.txt" % (fmt, w2c))
                    t.save(str(path))
                    back = snaps.read_trajectory(str(path), fmt, world_to_camera=w2c)
                    np.testing.assert_allclose(back.poses_3x4, p, atol=1e-12)
                    np.testing.assert_array_equal(back.frame_ids, t.frame_ids)
                    np.testing.assert_allclose(back.timestamps, t.timestamps)

    def test_bad_trajectories_are_refused(self):
        p = self.poses()
        p[2, 0, 0] = 2.0
        with self.assertRaisesRegex(ValueError, r"poses\[2\].*not a rotation"):
            snaps.Trajectory(p)
        with self.assertRaisesRegex(ValueError, "strictly increasing"):
            snaps.Trajectory(self.poses(), frame_ids=[0, 1, 1, 2, 3])
        with self.assertRaisesRegex(ValueError, "timestamps"):
            snaps.Trajectory(self.poses(), format="tum")
        with self.assertRaises(openable.InputError):
            snaps.Trajectory(self.poses(), format="kitty")
        with self.assertRaisesRegex(ValueError, "reference < query"):
            snaps.correct_discounted(snaps.Trajectory(self.poses()), [(1, 3)])

    def test_discounted_update_of_one_loop(self):
        # Pose 4 closes a loop with pose 0: it moves by gamma(0) of the gap, pose 3 by
        # gamma(1) of it, as Eq. 6 says.
        t = snaps.Trajectory(self.poses())
        out, shift = snaps.apply_discounted_update(t, 4, 0, similarity=1.0, alpha=1,
                                                   discount_length=300)
        gap = t.positions[0] - t.positions[4]
        np.testing.assert_allclose(shift, snaps.discount_gamma(0, 1) * gap)
        np.testing.assert_allclose(out.positions[3] - t.positions[3],
                                   snaps.discount_gamma(1, 1) * gap)
        self.assertAlmostEqual(snaps.discount_gamma(0, 1), 1 - math.exp(-3))
        np.testing.assert_allclose(out.poses[:, :3, :3], t.poses[:, :3, :3])

    def test_loops_from_matrix(self):
        t = snaps.Trajectory(self.poses(200))
        m = np.ones((200, 200), np.float32)
        m[150, 20] = m[20, 150] = 0.05
        m[160, 100] = 0.01  # only 60 frames back: inside the exclusion
        loops = snaps.loops_from_matrix(m, t, threshold=0.1, exclusion=100)
        self.assertEqual(len(loops), 1)
        self.assertEqual(loops[0][:2], (150, 20))
        self.assertAlmostEqual(loops[0][2], 0.95, places=6)


if __name__ == "__main__":
    unittest.main()
