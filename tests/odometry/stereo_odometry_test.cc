// StereoOdometry (OpenABLE/odometry/stereo_odometry.h): a rendered stereo pair of the synthetic
// room with a known baseline and motion, options, and the real EuRoC pairs 2 and 3 (0.5 s apart)
// against their ground-truth body poses.
#include "OpenABLE/odometry/stereo_odometry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "OpenABLE/odometry/mono_odometry.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/rectification.h"
#include "tests/odometry/synthetic_scene.h"
#include "tests/test_support.h"
#include "tests/tools/euroc_calibration.h"

namespace openable::odometry {
namespace {

using namespace odometry_test;  // NOLINT: the synthetic room is this file's vocabulary

constexpr double kBaseline = 0.2;  // metres

// The left and right images of a rectified rig whose left camera is at `pose`.
std::pair<cv::Mat, cv::Mat> RenderPair(const SyntheticRoom& room, const Eigen::Isometry3d& pose) {
  Eigen::Isometry3d right = pose;
  right.translation() += pose.linear() * Eigen::Vector3d(kBaseline, 0, 0);
  return {room.Render(kIntrinsics, kSize, pose), room.Render(kIntrinsics, kSize, right)};
}

// Tolerances: rotation within 0.3 degree, position within 3 cm plus 3% of the motion (depth from
// disparities of 3-25 pixels, located to a fraction of a pixel).
void CheckTwoPairs(StereoOdometryOptions options) {
  const SyntheticRoom room(11);
  const Eigen::Isometry3d second =
      Pose(3.0, Eigen::Vector3d(0.2, 1.0, 0.1), Eigen::Vector3d(0.3, -0.05, 0.8));
  StereoOdometry stereo(kIntrinsics, kBaseline, options);
  const auto [l0, r0] = RenderPair(room, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(stereo.Step(l0, r0).isApprox(Eigen::Isometry3d::Identity()));
  const auto [l1, r1] = RenderPair(room, second);
  const Eigen::Isometry3d p1 = stereo.Step(l1, r1);
  ASSERT_TRUE(stereo.last().ok) << stereo.last().note;
  const double rotation = Degrees(RotationAngle(second.linear().transpose() * p1.linear()));
  const double position = (p1.translation() - second.translation()).norm();
  std::printf(
      "%s %s wls %d: %d inliers of %d, rotation error %.3f deg, position error %.3f m, "
      "%.3f s\n",
      options.matcher.c_str(), options.features.c_str(), options.wls_filter, stereo.last().inliers,
      stereo.last().matches, rotation, position, stereo.last().seconds);
  EXPECT_GT(stereo.last().inliers, 50);
  EXPECT_LT(rotation, 0.3);
  EXPECT_LT(position, 0.03 + 0.03 * second.translation().norm());
}

TEST(StereoOdometry, RecoversAKnownMotionInASyntheticRoom) { CheckTwoPairs({}); }

TEST(StereoOdometry, RecoversItWithBlockMatchingAndOrbToo) {
  StereoOdometryOptions o;
  o.matcher = "bm";
  o.features = "ORB";
  CheckTwoPairs(o);
  StereoOdometryOptions plain;
  plain.wls_filter = false;
  CheckTwoPairs(plain);
}

TEST(StereoOdometry, DisparityOfTheSyntheticPairMatchesTheDepth) {
  // A fronto-parallel view of the back wall (z = 25 m from y = 0... the camera at z = 15 sees it
  // 10 m away): disparity f B / z = 400 x 0.2 / 10 = 8 pixels at the centre.
  const SyntheticRoom room(11);
  const auto [l, r] =
      RenderPair(room, Pose(0, Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, -1, 15)));
  const cv::Mat1f d = OdometryDisparity(l, r, StereoOdometryOptions());
  EXPECT_NEAR(d(240, 320), 8.0, 0.25);
  EXPECT_EQ(d(240, 10), 0.0f);  // the left band has no disparity
}

TEST(StereoOdometry, FallsBackToConstantVelocityOnAFeaturelessPair) {
  const SyntheticRoom room(11);
  StereoOdometry stereo(kIntrinsics, kBaseline, StereoOdometryOptions());
  const auto [l0, r0] = RenderPair(room, Eigen::Isometry3d::Identity());
  stereo.Step(l0, r0);
  const auto [l1, r1] =
      RenderPair(room, Pose(0, Eigen::Vector3d::UnitY(), Eigen::Vector3d(0, 0, 0.5)));
  const Eigen::Isometry3d p1 = stereo.Step(l1, r1);
  ASSERT_TRUE(stereo.last().ok);
  const cv::Mat flat(kSize, CV_8UC1, cv::Scalar(128));
  const Eigen::Isometry3d p2 = stereo.Step(flat, flat);
  EXPECT_FALSE(stereo.last().ok);
  EXPECT_NE(stereo.last().note.find("constant velocity"), std::string::npos);
  EXPECT_TRUE((p1.inverse() * p2).isApprox(p1, 1e-9));  // the same motion again
}

TEST(StereoOdometryOptions, CheckNamesTheField) {
  const auto expect = [](auto change, const std::string& field) {
    StereoOdometryOptions o;
    change(o);
    testing::ExpectInputError([&] { o.Check(); }, {"StereoOdometryOptions." + field});
  };
  expect([](StereoOdometryOptions& o) { o.matcher = "census"; }, "matcher");
  expect([](StereoOdometryOptions& o) { o.wls_lambda = 0; }, "wls_lambda");
  expect([](StereoOdometryOptions& o) { o.wls_sigma = -1; }, "wls_sigma");
  expect([](StereoOdometryOptions& o) { o.disparity.num_disparities = 60; },
         "disparity.num_disparities");
  expect([](StereoOdometryOptions& o) { o.disparity.block_size = 4; }, "disparity.block_size");
  expect([](StereoOdometryOptions& o) { o.matcher = "bm", o.disparity.block_size = 3; },
         "disparity.block_size");
  expect([](StereoOdometryOptions& o) { o.features = "AKAZE"; }, "features");
  expect([](StereoOdometryOptions& o) { o.max_features = 0; }, "max_features");
  expect([](StereoOdometryOptions& o) { o.ratio_test = 2; }, "ratio_test");
  expect([](StereoOdometryOptions& o) { o.max_depth = 0; }, "max_depth");
  expect([](StereoOdometryOptions& o) { o.pnp_reprojection_px = 0; }, "pnp_reprojection_px");
  expect([](StereoOdometryOptions& o) { o.pnp_iterations = 0; }, "pnp_iterations");
  expect([](StereoOdometryOptions& o) { o.pnp_confidence = 1; }, "pnp_confidence");
  expect([](StereoOdometryOptions& o) { o.min_inliers = 3; }, "min_inliers");
  EXPECT_NO_THROW(StereoOdometryOptions().Check());
  testing::ExpectInputError([] { StereoOdometry(kIntrinsics, 0.0, StereoOdometryOptions()); },
                            {"baseline"});
}

// ---- EuRoC V1_01 pairs 2 and 3 (0.5 s apart), raw images rectified with the toolbox.

std::string EurocDir() { return testing::DatasetsDir() + "/euroc_stereo_pairs"; }

// Ground-truth body pose (world from body) of image `index` in gt_poses.txt: rows
// "role index timestamp qw qx qy qz tx ty tz".
Eigen::Isometry3d EurocBodyPose(int index) {
  std::ifstream in(EurocDir() + "/gt_poses.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    std::string role;
    int i = -1;
    long long stamp = 0;
    double qw, qx, qy, qz, tx, ty, tz;
    s >> role >> i >> stamp >> qw >> qx >> qy >> qz >> tx >> ty >> tz;
    if (s && i == index) {
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
      pose.translation() = Eigen::Vector3d(tx, ty, tz);
      return pose;
    }
  }
  ADD_FAILURE() << "no pose of image " << index;
  return Eigen::Isometry3d::Identity();
}

TEST(StereoOdometry, EurocPairs3To2AgreeWithTheGroundTruth) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const std::string calibration_file = testing::TempDir() + "/euroc.yaml";
  ASSERT_TRUE(testing::WriteEurocCalibration(EurocDir(), calibration_file));
  const StereoCalibration calibration = LoadStereoCalibration(calibration_file);
  const cv::Size size(752, 480);
  const StereoRectifier rectifier(calibration, size);
  const cv::Matx34d& P = rectifier.ProjectionLeft();
  const Intrinsics intrinsics{P(0, 0), P(1, 1), P(0, 2), P(1, 2)};
  const double baseline = rectifier.Baseline();  // metres: Kalibr's T_BS are in metres
  EXPECT_NEAR(baseline, 0.11, 0.005);

  StereoOdometry stereo(intrinsics, baseline, StereoOdometryOptions());
  Eigen::Isometry3d pose;
  for (const int i : {3, 2}) {  // time order: image 3 (t = 400.26 s), then image 2 (400.76 s)
    const cv::Mat left =
        cv::imread(EurocDir() + "/left_img_" + std::to_string(i) + ".png", cv::IMREAD_GRAYSCALE);
    const cv::Mat right =
        cv::imread(EurocDir() + "/right_img_" + std::to_string(i) + ".png", cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(left.empty());
    ASSERT_FALSE(right.empty());
    cv::Mat left_rectified, right_rectified;
    rectifier.Rectify(left, right, left_rectified, right_rectified);
    // A valid disparity map: most pixels right of the band have a disparity, in the range of
    // an indoor room seen with f ~ 440 px and B = 0.11 m (0.7-10 m: 5-70 px).
    const cv::Mat1f d = OdometryDisparity(left_rectified, right_rectified, StereoOdometryOptions());
    const cv::Mat1f inside = d.colRange(64, d.cols);
    const double valid = cv::countNonZero(inside > 0) / double(inside.total());
    EXPECT_GT(valid, 0.8) << "image " << i;
    std::vector<float> values(inside.begin(), inside.end());
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    EXPECT_GT(values[values.size() / 2], 5.0f);
    EXPECT_LT(values[values.size() / 2], 64.0f);
    pose = stereo.Step(left_rectified, right_rectified);
  }
  ASSERT_TRUE(stereo.last().ok) << stereo.last().note;

  // Ground truth, camera frame: T_C3_C2 = T_BS^-1 T_WB3^-1 T_WB2 T_BS (the rectifying rotation
  // conjugates it once more, which changes neither the angle nor the length). By hand from
  // gt_poses.txt: 15.58 degrees and 0.317 m.
  testing::EurocCamera left_camera;
  ASSERT_TRUE(testing::ReadEurocCamera(EurocDir() + "/sensorLeft.yaml", left_camera));
  Eigen::Matrix4d body_from_sensor;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) body_from_sensor(r, c) = left_camera.body_from_sensor(r, c);
  const Eigen::Isometry3d bs(body_from_sensor);
  const Eigen::Isometry3d truth = bs.inverse() * EurocBodyPose(3).inverse() * EurocBodyPose(2) * bs;
  const double true_angle = Degrees(RotationAngle(truth.linear()));
  const double true_length = truth.translation().norm();
  EXPECT_NEAR(true_angle, 15.58, 0.01);
  EXPECT_NEAR(true_length, 0.317, 0.001);
  const double angle = Degrees(RotationAngle(pose.linear()));
  const double length = pose.translation().norm();
  // Direction compared in the rectified frame: R_rect = rectifying rotation of the left camera.
  Eigen::Matrix3d rect;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rect(r, c) = rectifier.RectifyingRotationLeft()(r, c);
  const Eigen::Vector3d true_direction = (rect * truth.translation()).normalized();
  const double direction = Degrees(
      std::acos(std::clamp(true_direction.dot(pose.translation().normalized()), -1.0, 1.0)));
  std::printf(
      "EuRoC 3->2: %d inliers of %d; angle %.2f deg (truth %.2f), length %.3f m "
      "(truth %.3f), direction error %.1f deg\n",
      stereo.last().inliers, stereo.last().matches, angle, true_angle, length, true_length,
      direction);
  // Tolerances: rotation angle within 1 degree, length within 3 cm, direction within 10 degrees.
  EXPECT_NEAR(angle, true_angle, 1.0);
  EXPECT_NEAR(length, true_length, 0.03);
  EXPECT_LT(direction, 10.0);
}

}  // namespace
}  // namespace openable::odometry
