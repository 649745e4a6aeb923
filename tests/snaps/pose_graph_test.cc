// Pose-graph correction: synthetic squares with injected drift, the robust kernel against a
// wrong loop, and the SO-DSO trajectories of KITTI 00 and 06 with their ground-truth loops.
#include "OpenABLE/snaps/pose_graph.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/snaps/loops.h"
#include "OpenABLE/snaps/trajectory.h"
#include "tests/test_support.h"

namespace openable::snaps {
namespace {

using openable::testing::DatasetsDir;
using openable::testing::ExpectInputError;

Eigen::Isometry3d Step(double forward, double yaw) {
  Eigen::Isometry3d s = Eigen::Isometry3d::Identity();
  s.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  s.translation() = Eigen::Vector3d(0, 0, forward);
  return s;
}

// `laps` times round a square of 4 sides x 25 steps of 1 m in the x-z plane (KITTI's ground),
// turning 90 degrees at each corner: 100 laps + 1 poses, pose 100 k at the start.
// `yaw_drift` (rad per step) and `scale_drift` (relative) corrupt each step when `drift`.
Trajectory Square(int laps, double yaw_drift = 0, double scale_drift = 0) {
  Trajectory t;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  t.poses.push_back(pose);
  t.frame_ids.push_back(0);
  for (int k = 1; k <= 100 * laps; ++k) {
    const bool corner = k % 25 == 0;
    pose = pose * Step(1.0 + scale_drift, (corner ? M_PI / 2 : 0) + yaw_drift);
    t.poses.push_back(pose);
    t.frame_ids.push_back(k);
  }
  return t;
}

double MeanDistance(const Trajectory& a, const Trajectory& b) {
  double sum = 0;
  for (int i = 0; i < a.Size(); ++i)
    sum += (a.poses[i].translation() - b.poses[i].translation()).norm();
  return sum / a.Size();
}

TEST(CorrectPoseGraph, SquareLoopCloses) {
  const Trajectory truth = Square(1);
  const Trajectory drifting = Square(1, 0.004, 0.01);
  const double gap = (drifting.poses[100].translation() - drifting.poses[0].translation()).norm();
  ASSERT_GT(gap, 5.0);  // the drift opens the loop by metres
  PoseGraphOptions options;
  options.loop_weight = 1e8;  // a hard loop: it must close
  options.robust_kernel = RobustKernel::kNone;
  PoseGraphReport report;
  const Trajectory corrected = CorrectPoseGraph(drifting, {{100, 0, 1.0}}, options, &report);
  ASSERT_EQ(corrected.Size(), 101);
  EXPECT_TRUE(report.converged);
  EXPECT_GT(report.iterations, 1);
  EXPECT_LT(report.final_cost, 1e-3 * report.initial_cost);
  const double closure =
      (corrected.poses[100].translation() - corrected.poses[0].translation()).norm();
  EXPECT_LT(closure, 1e-6 * 100);  // relative to the 100 m of the loop
  // Gauge: the first pose does not move.
  EXPECT_TRUE(corrected.poses[0].isApprox(drifting.poses[0], 1e-12));
  // A position-only loop cannot tell heading drift from a bend: the least-squares answer
  // closes the loop and is nearer the truth, not equal to it.
  const double before = MeanDistance(drifting, truth);
  const double after = MeanDistance(corrected, truth);
  std::printf("square: mean distance to the truth %.3f m before, %.3f m after (%d steps, %.4f s)\n",
              before, after, report.iterations, report.seconds);
  EXPECT_LT(after, before);
}

TEST(CorrectPoseGraph, TranslationDriftIsRemovedExactly) {
  // Drift of a constant 3 cm per step along world x (rotations exact). With rotations held
  // (a huge rotation weight), the least-squares correction of equal translation weights spreads
  // the 3 m gap evenly over the 100 steps: the truth itself.
  const Trajectory truth = Square(1);
  Trajectory drifting = truth;
  for (int k = 0; k < drifting.Size(); ++k) drifting.poses[k].translation().x() += 0.03 * k;
  PoseGraphOptions options;
  options.loop_weight = 1e8;
  options.odometry_rotation_weight = 1e12;
  options.robust_kernel = RobustKernel::kNone;
  const Trajectory corrected = CorrectPoseGraph(drifting, {{100, 0, 1.0}}, options);
  EXPECT_NEAR(MeanDistance(drifting, truth), 1.5, 1e-9);
  double worst = 0;
  for (int k = 0; k < truth.Size(); ++k) {
    worst =
        std::max(worst, (corrected.poses[k].translation() - truth.poses[k].translation()).norm());
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(CorrectPoseGraph, ExactOdometryAndExactLoopIsAFixedPoint) {
  const Trajectory truth = Square(1);
  PoseGraphReport report;
  const Trajectory corrected = CorrectPoseGraph(truth, {{100, 0, 1.0}}, {}, &report);
  EXPECT_LT(MeanDistance(corrected, truth), 1e-9);
  EXPECT_LT(report.initial_cost, 1e-20);
}

TEST(CorrectPoseGraph, NoLoopsGiveTheInputBack) {
  const Trajectory drifting = Square(1, 0.004, 0.01);
  PoseGraphReport report;
  const Trajectory corrected = CorrectPoseGraph(drifting, {}, {}, &report);
  ASSERT_EQ(corrected.Size(), drifting.Size());
  for (int i = 0; i < drifting.Size(); ++i) {
    EXPECT_EQ(corrected.poses[i].matrix(), drifting.poses[i].matrix());
  }
  EXPECT_EQ(corrected.frame_ids, drifting.frame_ids);
  EXPECT_EQ(report.iterations, 0);
}

TEST(CorrectPoseGraph, KnownRelativePoseLoopClosesRotationToo) {
  const Trajectory drifting = Square(1, 0.004, 0.0);
  RelativeLoop loop;
  loop.query = 100;
  loop.reference = 0;  // identity: the same pose, same heading
  PoseGraphOptions options;
  options.loop_weight = 1e8;
  options.robust_kernel = RobustKernel::kNone;
  const Trajectory corrected = CorrectPoseGraph(drifting, {}, {loop}, options);
  const Eigen::Isometry3d relative = corrected.poses[0].inverse() * corrected.poses[100];
  EXPECT_LT(relative.translation().norm(), 1e-4);
  EXPECT_LT(Eigen::AngleAxisd(relative.linear()).angle(), 1e-6);
  // Without it the heading stays off by 100 x 0.004 rad.
  const Eigen::Isometry3d open = drifting.poses[0].inverse() * drifting.poses[100];
  EXPECT_NEAR(Eigen::AngleAxisd(open.linear()).angle(), 0.4, 1e-9);
  // A constant heading drift lies in what a full-pose loop observes: much nearer the truth.
  const Trajectory truth = Square(1);
  std::printf("relative loop: mean distance to the truth %.3f m before, %.3f m after\n",
              MeanDistance(drifting, truth), MeanDistance(corrected, truth));
  EXPECT_LT(MeanDistance(corrected, truth), 0.2 * MeanDistance(drifting, truth));
}

TEST(CorrectPoseGraph, RobustKernelLimitsAWrongLoop) {
  // Two laps: the second lap revisits the first, 100 correct loop pairs; one wrong pair joins
  // pose 160 (second lap, third side) to pose 10 (first side), about 25 m apart.
  const Trajectory drifting = Square(2, 0.002, 0.005);
  const Trajectory truth = Square(2);
  std::vector<LoopPair> loops;
  for (int k = 100; k <= 200; k += 4) loops.push_back({k, k - 100, 1.0});
  std::vector<LoopPair> with_wrong = loops;
  for (int k = 0; k < 3; ++k) with_wrong.push_back({160 + k, 10 + k, 1.0});
  PoseGraphOptions robust;  // defaults: Huber
  PoseGraphOptions plain;
  plain.robust_kernel = RobustKernel::kNone;
  const Trajectory clean = CorrectPoseGraph(drifting, loops, robust, nullptr);
  const Trajectory huber = CorrectPoseGraph(drifting, with_wrong, robust, nullptr);
  const Trajectory none = CorrectPoseGraph(drifting, with_wrong, plain, nullptr);
  PoseGraphOptions cauchy_options;
  cauchy_options.robust_kernel = RobustKernel::kCauchy;
  const Trajectory cauchy = CorrectPoseGraph(drifting, with_wrong, cauchy_options, nullptr);
  const double moved_huber = MeanDistance(huber, clean);
  const double moved_none = MeanDistance(none, clean);
  const double moved_cauchy = MeanDistance(cauchy, clean);
  std::printf(
      "wrong loop: input %.3f m from the truth, clean %.3f m; the wrong pairs move it "
      "%.3f m (huber), %.3f m (cauchy), %.3f m (no kernel)\n",
      MeanDistance(drifting, truth), MeanDistance(clean, truth), moved_huber, moved_cauchy,
      moved_none);
  EXPECT_LT(MeanDistance(clean, truth), MeanDistance(drifting, truth));
  EXPECT_GT(moved_none, 1.0);
  EXPECT_LT(moved_huber, 0.3 * moved_none);
  EXPECT_LT(moved_cauchy, 0.3 * moved_none);
}

TEST(CorrectPoseGraph, OptionsAndIndicesAreChecked) {
  const Trajectory t = Square(1);
  PoseGraphOptions options;
  options.loop_weight = -1;
  ExpectInputError(
      [&] {
        CorrectPoseGraph(t, {{100, 0, 1}}, options);
      },
      {"loop_weight", "-1", "> 0"});
  options = PoseGraphOptions();
  options.max_iterations = 0;
  ExpectInputError([&] { options.Check(); }, {"max_iterations", ">= 1"});
  EXPECT_THROW(CorrectPoseGraph(t, {{101, 0, 1}}, {}), std::logic_error);
  EXPECT_THROW(CorrectPoseGraph(t, {{5, 5, 1}}, {}), std::logic_error);
  ExpectInputError([] { ParseRobustKernel("tukey", "Robust_kernel"); },
                   {"Robust_kernel", "\"tukey\"", "huber", "cauchy"});
  EXPECT_EQ(ParseRobustKernel("Huber", "k"), RobustKernel::kHuber);
}

// ---------------------------------------------------------------------------------------------
// Real data: SO-DSO keyframes of KITTI 00 and 06 with the ground-truth loop pairs.

void CorrectSoDso(const std::string& sequence, const std::string& pairs_file) {
  const std::string root = DatasetsDir() + "/kitti_trajectories";
  OPENABLE_REQUIRE_PATH(root);
  const Trajectory vo =
      ReadTrajectory(root + "/vo_so_dso/seq" + sequence + "/poses_history_file.txt",
                     TrajectoryFormat::kKittiWithId, true);
  const Trajectory truth =
      ReadTrajectory(root + "/poses/" + sequence + ".txt", TrajectoryFormat::kKitti);
  const std::vector<int> association = AssociateWithTruth(vo, truth, 0, "truth");
  // Pairs on keyframes, the middle reference of each run (see MiddleOfRuns).
  // Pairs beyond the last keyframe (the VO stops a few frames before the sequence) are dropped.
  int dropped = 0, outside = 0;
  const std::vector<LoopPair> pairs =
      LoopsFromCsv(root + "/loop_pairs/" + pairs_file, vo, 0, &dropped, &outside);
  const std::vector<LoopPair> loops = MiddleOfRuns(pairs, vo);
  const int total = static_cast<int>(pairs.size()) + dropped + outside;
  PoseGraphReport report;
  const Trajectory corrected = CorrectPoseGraph(vo, loops, PoseGraphOptions(), &report);
  const TrajectoryError before = AbsoluteTrajectoryError(vo, truth, association, false);
  const TrajectoryError after = AbsoluteTrajectoryError(corrected, truth, association, false);
  const TrajectoryError before_aligned = AbsoluteTrajectoryError(vo, truth, association, true);
  const TrajectoryError after_aligned =
      AbsoluteTrajectoryError(corrected, truth, association, true);
  std::printf(
      "KITTI %s SO-DSO: %d keyframes, %d of %d ground-truth loop pairs on keyframes\n"
      "  unaligned: mean %.2f -> %.2f m (%+.1f %%), rmse %.2f -> %.2f m, max %.2f -> %.2f\n"
      "  aligned:   mean %.2f -> %.2f m (%+.1f %%), rmse %.2f -> %.2f m\n"
      "  solver: %d steps, cost %.4g -> %.4g, %.3f s, converged %d\n",
      sequence.c_str(), vo.Size(), static_cast<int>(loops.size()), total, before.mean, after.mean,
      -100 * (1 - after.mean / before.mean), before.rmse, after.rmse, before.max, after.max,
      before_aligned.mean, after_aligned.mean,
      -100 * (1 - after_aligned.mean / before_aligned.mean), before_aligned.rmse,
      after_aligned.rmse, report.iterations, report.initial_cost, report.final_cost, report.seconds,
      report.converged ? 1 : 0);
  // What the model minimises: the loop pairs' positions meet (mean gap down by half at least).
  const auto mean_gap = [&loops](const Trajectory& t) {
    double sum = 0;
    for (const LoopPair& l : loops) {
      sum += (t.poses[l.query].translation() - t.poses[l.reference].translation()).norm();
    }
    return sum / static_cast<double>(loops.size());
  };
  std::printf("  loop pairs' position gap: %.2f -> %.2f m\n", mean_gap(vo), mean_gap(corrected));
  EXPECT_LT(mean_gap(corrected), 0.5 * mean_gap(vo));
  // The paper's figure (mean deviation down by 65 %) is NOT reached on SO-DSO with these loop
  // pairs (see docs/benchmarks.md, "SNAPS and odometry"): reported above, not asserted.
  std::printf("  paper: mean deviation -65 %%; here (unaligned) %+.1f %%\n",
              -100 * (1 - after.mean / before.mean));
}

TEST(CorrectPoseGraphKitti, SoDso00) { CorrectSoDso("00", "groundTruth_KITTI00.pairs.csv"); }
TEST(CorrectPoseGraphKitti, SoDso06) { CorrectSoDso("06", "kitti06GroundTruth.pairs.csv"); }

}  // namespace
}  // namespace openable::snaps
