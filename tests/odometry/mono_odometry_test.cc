// MonoOdometry (OpenABLE/odometry/mono_odometry.h): a synthetic room seen from two known poses,
// options, the constant-velocity fallback, and KITTI 00 frames 0-199 against the ground truth.
#include "OpenABLE/odometry/mono_odometry.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "OpenABLE/snaps/trajectory.h"
#include "tests/odometry/synthetic_scene.h"
#include "tests/test_support.h"

namespace openable::odometry {
namespace {

using namespace odometry_test;  // NOLINT: the synthetic room is this file's vocabulary

// Relative pose error of `estimate` against `truth`: rotation angle (degrees) of
// R_truth^T R_estimate and angle (degrees) between the translations.
void ExpectClosePose(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
                     double max_rotation_deg, double max_direction_deg) {
  const double rotation = Degrees(RotationAngle(truth.linear().transpose() * estimate.linear()));
  const double direction = Degrees(std::acos(std::clamp(
      truth.translation().normalized().dot(estimate.translation().normalized()), -1.0, 1.0)));
  std::printf("rotation error %.3f deg, translation direction error %.3f deg\n", rotation,
              direction);
  EXPECT_LT(rotation, max_rotation_deg);
  EXPECT_LT(direction, max_direction_deg);
}

// Tolerances for two views of the synthetic room: rotation within 0.5 degree, translation
// direction within `max_direction_deg` (3 degrees for SIFT's sub-pixel keypoints, 5 for ORB's
// pixel-level ones), and the translation length exactly the given step length.
void CheckTwoViews(const std::string& features, double ransac_px, double max_direction_deg) {
  const SyntheticRoom room(7);
  const Eigen::Isometry3d first = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d second =
      Pose(3.0, Eigen::Vector3d(0.2, 1.0, 0.1), Eigen::Vector3d(0.3, -0.05, 0.8));
  MonoOdometryOptions options;
  options.features = features;
  options.ransac_threshold_px = ransac_px;
  MonoOdometry mono(kIntrinsics, options);
  const Eigen::Isometry3d p0 = mono.Step(room.Render(kIntrinsics, kSize, first), 0.0);
  EXPECT_TRUE(p0.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(mono.last().note, "first frame");
  const double length = second.translation().norm();
  const Eigen::Isometry3d p1 = mono.Step(room.Render(kIntrinsics, kSize, second), length);
  EXPECT_TRUE(mono.last().ok) << mono.last().note;
  EXPECT_GT(mono.last().inliers, 100);
  EXPECT_NEAR(p1.translation().norm(), length, 1e-9);
  ExpectClosePose(p1, second, 0.5, max_direction_deg);
}

TEST(MonoOdometry, RecoversAKnownMotionInASyntheticRoomWithSift) {
  CheckTwoViews("SIFT", 0.5, 3.0);
}
TEST(MonoOdometry, RecoversAKnownMotionInASyntheticRoomWithOrb) { CheckTwoViews("orb", 1.0, 5.0); }

TEST(MonoOdometry, UnknownStepLengthGivesUnitSteps) {
  const SyntheticRoom room(7);
  MonoOdometry mono(kIntrinsics, MonoOdometryOptions());
  mono.Step(room.Render(kIntrinsics, kSize, Eigen::Isometry3d::Identity()), -1);
  const Eigen::Isometry3d p =
      mono.Step(room.Render(kIntrinsics, kSize,
                            Pose(1.0, Eigen::Vector3d::UnitY(), Eigen::Vector3d(0.0, 0.0, 0.5))),
                -1);
  EXPECT_NEAR(p.translation().norm(), 1.0, 1e-9);
  EXPECT_GT(p.translation().z(), 0.99);  // forward
}

TEST(MonoOdometry, FallsBackToConstantVelocityOnAFeaturelessFrame) {
  const SyntheticRoom room(7);
  MonoOdometry mono(kIntrinsics, MonoOdometryOptions());
  const Eigen::Isometry3d step = Pose(0.0, Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 0, 0.5));
  mono.Step(room.Render(kIntrinsics, kSize, Eigen::Isometry3d::Identity()), 0);
  const Eigen::Isometry3d p1 = mono.Step(room.Render(kIntrinsics, kSize, step), 0.5);
  ASSERT_TRUE(mono.last().ok);
  // A uniform frame: no features, so the step repeats the previous motion with the new length.
  const Eigen::Isometry3d p2 = mono.Step(cv::Mat(kSize, CV_8UC1, cv::Scalar(128)), 1.0);
  EXPECT_FALSE(mono.last().ok);
  EXPECT_NE(mono.last().note.find("constant velocity"), std::string::npos) << mono.last().note;
  const Eigen::Isometry3d motion = p1.inverse() * p2;
  EXPECT_NEAR(motion.translation().norm(), 1.0, 1e-9);
  EXPECT_NEAR(motion.translation().normalized().dot(p1.translation().normalized()), 1.0, 1e-9);
  EXPECT_TRUE(motion.linear().isApprox(p1.linear(), 1e-9));
}

TEST(MonoOdometry, IsDeterministic) {
  const SyntheticRoom room(3);
  const cv::Mat a = room.Render(kIntrinsics, kSize, Eigen::Isometry3d::Identity());
  const cv::Mat b = room.Render(kIntrinsics, kSize,
                                Pose(2.0, Eigen::Vector3d::UnitY(), Eigen::Vector3d(0.2, 0, 0.6)));
  Eigen::Isometry3d results[2];
  for (auto& r : results) {
    MonoOdometry mono(kIntrinsics, MonoOdometryOptions());
    mono.Step(a, 0);
    r = mono.Step(b, 0.63);
  }
  EXPECT_TRUE(results[0].matrix() == results[1].matrix());
}

TEST(MonoOdometryOptions, CheckNamesTheField) {
  const auto expect = [](auto change, const std::string& field) {
    MonoOdometryOptions o;
    change(o);
    testing::ExpectInputError([&] { o.Check(); }, {"MonoOdometryOptions." + field});
    testing::ExpectInputError([&] { MonoOdometry(kIntrinsics, o); },
                              {"MonoOdometryOptions." + field});
  };
  expect([](MonoOdometryOptions& o) { o.features = "SURF"; }, "features");
  expect([](MonoOdometryOptions& o) { o.max_features = 3; }, "max_features");
  expect([](MonoOdometryOptions& o) { o.ratio_test = 0; }, "ratio_test");
  expect([](MonoOdometryOptions& o) { o.ratio_test = 1.5; }, "ratio_test");
  expect([](MonoOdometryOptions& o) { o.ransac_threshold_px = 0; }, "ransac_threshold_px");
  expect([](MonoOdometryOptions& o) { o.ransac_confidence = 1; }, "ransac_confidence");
  expect([](MonoOdometryOptions& o) { o.min_inliers = 4; }, "min_inliers");
  EXPECT_NO_THROW(MonoOdometryOptions().Check());
  testing::ExpectInputError(
      [] {
        MonoOdometry(Intrinsics{0, 1, 1, 1}, MonoOdometryOptions());
      },
      {"fx"});
}

// KITTI 00 frames 0-199 (145 m), half-size left frames, each step's length from the ground
// truth. Measured (SIFT, defaults): ATE mean 1.66 m unaligned, 0.12 m aligned, no fallback
// step. Bounds with margin: unaligned mean < 4 m, aligned mean < 0.5 m, at most 2 fallbacks.
TEST(MonoOdometry, KittiFrames0To199StayCloseToTheGroundTruth) {
  const std::string dir = testing::DatasetsDir() + "/kitti00_first1700";
  OPENABLE_REQUIRE_PATH(dir);
  const KittiCalibration calibration = ReadKittiCalibration(dir + "/calib.txt", 0.5);
  const snaps::Trajectory truth =
      snaps::ReadTrajectory(dir + "/poses/00_first1700.txt", snaps::TrajectoryFormat::kKitti);
  MonoOdometry mono(calibration.left, MonoOdometryOptions());
  snaps::Trajectory estimate;
  int fallbacks = 0;
  for (int i = 0; i < 200; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/image_0/%06d.png", i);
    const cv::Mat gray = cv::imread(dir + name, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(gray.empty()) << name;
    const double step =
        i == 0 ? 0 : (truth.poses[i].translation() - truth.poses[i - 1].translation()).norm();
    estimate.poses.push_back(truth.poses[0] * mono.Step(gray, step));
    estimate.frame_ids.push_back(i);
    if (i > 0 && !mono.last().ok) ++fallbacks;
  }
  const std::vector<int> association = snaps::AssociateWithTruth(estimate, truth, 0, "truth");
  const auto unaligned = snaps::AbsoluteTrajectoryError(estimate, truth, association, false);
  const auto aligned = snaps::AbsoluteTrajectoryError(estimate, truth, association, true);
  std::printf("KITTI 00 0-199 mono: ATE mean %.2f m unaligned, %.2f m aligned, %d fallbacks\n",
              unaligned.mean, aligned.mean, fallbacks);
  EXPECT_LT(unaligned.mean, 4.0);
  EXPECT_LT(aligned.mean, 0.5);
  EXPECT_LE(fallbacks, 2);
}

}  // namespace
}  // namespace openable::odometry
