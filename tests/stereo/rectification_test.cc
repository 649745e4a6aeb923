// Rectification (OpenABLE/stereo/rectification.h) on the real EuRoC pairs: after it, a scene
// point lies on the same row of the left and the right image.
#include "OpenABLE/stereo/rectification.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/features2d.hpp>
#include <vector>

#include "OpenABLE/stereo/calibration.h"
#include "tests/stereo/stereo_test_util.h"

namespace openable {
namespace {

using namespace stereo_test;  // NOLINT: this file's vocabulary

// ORB matches between two images (mutual best, Hamming <= 40); their row and column offsets.
struct Offsets {
  std::vector<double> dy, dx;
};
Offsets MatchOffsets(const cv::Mat& left, const cv::Mat& right) {
  const cv::Ptr<cv::ORB> orb = cv::ORB::create(2000);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  orb->detectAndCompute(left, cv::noArray(), kl, dl);
  orb->detectAndCompute(right, cv::noArray(), kr, dr);
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  std::vector<cv::DMatch> matches;
  matcher.match(dl, dr, matches);
  Offsets o;
  for (const cv::DMatch& m : matches) {
    if (m.distance > 40) continue;
    o.dy.push_back(kl[m.queryIdx].pt.y - kr[m.trainIdx].pt.y);
    o.dx.push_back(kl[m.queryIdx].pt.x - kr[m.trainIdx].pt.x);
  }
  return o;
}

double MedianAbs(std::vector<double> v) {
  for (double& x : v) x = std::abs(x);
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(StereoRectifier, LinesUpCorrespondingRowsOfTheEurocPairs) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const StereoCalibration c = LoadStereoCalibration(EurocCalibrationFile());
  const StereoRectifier rectifier(c, cv::Size(752, 480));
  for (int i = 0; i < 4; ++i) {
    const cv::Mat left = EurocLeft(i), right = EurocRight(i);
    ASSERT_FALSE(left.empty());
    cv::Mat left_r, right_r;
    rectifier.Rectify(left, right, left_r, right_r);
    ASSERT_EQ(left_r.size(), left.size());
    ASSERT_EQ(left_r.type(), CV_8UC1);
    const Offsets raw = MatchOffsets(left, right), rect = MatchOffsets(left_r, right_r);
    ASSERT_GE(raw.dy.size(), 100u) << "pair " << i;
    ASSERT_GE(rect.dy.size(), 100u) << "pair " << i;
    const double before = MedianAbs(raw.dy), after = MedianAbs(rect.dy);
    std::cout << "pair " << i << ": median |dy| " << before << " px raw (" << raw.dy.size()
              << " matches), " << after << " px rectified (" << rect.dy.size() << ")\n";
    EXPECT_LT(after, 1.0) << "pair " << i;
    EXPECT_GT(before, 2.0 * after) << "pair " << i;
    // Rectified matches sit on the left's row or near it for most pairs: 80% within 1.5 px.
    int close = 0;
    for (double dy : rect.dy) close += std::abs(dy) <= 1.5;
    EXPECT_GT(close, 0.8 * rect.dy.size()) << "pair " << i;
    // With CALIB_ZERO_DISPARITY, x_left - x_right is the disparity: positive.
    EXPECT_GT(MedianAbs(rect.dx), 0.0);
    int positive = 0;
    for (double dx : rect.dx) positive += dx > 0;
    EXPECT_GT(positive, 0.8 * rect.dx.size()) << "pair " << i;
  }
}

TEST(StereoRectifier, BaselineAndFocalOfTheRectifiedCameras) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const StereoCalibration c = LoadStereoCalibration(EurocCalibrationFile());
  const StereoRectifier rectifier(c, cv::Size(752, 480));
  EXPECT_NEAR(rectifier.Baseline(), cv::norm(c.translation), 1e-9);
  // alpha 0 zooms in (every pixel valid): the focal grows a little beyond the raw ~458 px.
  EXPECT_GT(rectifier.Focal(), 400.0);
  EXPECT_LT(rectifier.Focal(), 700.0);
  // Rectified cameras share the principal point (CALIB_ZERO_DISPARITY).
  EXPECT_DOUBLE_EQ(rectifier.ProjectionLeft()(0, 2), rectifier.ProjectionRight()(0, 2));
  EXPECT_DOUBLE_EQ(rectifier.ProjectionLeft()(1, 2), rectifier.ProjectionRight()(1, 2));
  // alpha 0: no black border in the rectified image of a real frame.
  cv::Mat left_r, right_r;
  rectifier.Rectify(EurocLeft(0), EurocRight(0), left_r, right_r);
  EXPECT_GT(cv::countNonZero(left_r.col(0)), 470);
  EXPECT_GT(cv::countNonZero(right_r.row(479)), 740);
}

TEST(StereoRectifier, IdealCameraIsLeftAlone) {
  // Already rectified, undistorted cameras: rectification is the identity (up to remap's
  // fixed-point interpolation).
  const cv::Size size(160, 120);
  const StereoCalibration c = LoadStereoCalibration(IdealCalibrationFile(size));
  const StereoRectifier rectifier(c, size);
  const cv::Mat image = Texture(size, 5);
  cv::Mat left_r, right_r;
  rectifier.Rectify(image, image, left_r, right_r);
  cv::Mat diff;
  cv::absdiff(left_r, image, diff);
  EXPECT_LE(cv::norm(diff, cv::NORM_INF), 1.0);
  EXPECT_NEAR(rectifier.Focal(), 100.0, 1e-6);
}

}  // namespace
}  // namespace openable
