// SGBM disparity (OpenABLE/stereo/disparity.h): a synthetic shift of known size, and the real
// EuRoC pairs checked against sparse ORB correspondences and the room's depths.
#include "OpenABLE/stereo/disparity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <opencv2/features2d.hpp>
#include <vector>

#include "OpenABLE/stereo/rectification.h"
#include "OpenABLE/stereo/stereo_source.h"
#include "tests/stereo/stereo_test_util.h"

namespace openable {
namespace {

using namespace stereo_test;  // NOLINT: this file's vocabulary

TEST(DisparityOptions, ScaleWithTheImageWidth) {
  EXPECT_EQ(DisparityOptions::ForWidth(752).num_disparities, 128);
  EXPECT_EQ(DisparityOptions::ForWidth(512).num_disparities, 128);
  EXPECT_EQ(DisparityOptions::ForWidth(376).num_disparities, 80);  // 94 -> 80
  EXPECT_EQ(DisparityOptions::ForWidth(64).num_disparities, 16);
  EXPECT_EQ(DisparityOptions::ForWidth(752).block_size, 5);
  EXPECT_EQ(DisparityOptions::ForWidth(200).block_size, 3);
  DisparityOptions bad;
  bad.num_disparities = 100;
  EXPECT_THROW(bad.Check(), std::logic_error);
}

TEST(ComputeDisparity, RecoversAKnownShift) {
  // The right image is the left one moved 20 px to the left: every pixel has disparity 20.
  const cv::Size size(320, 160);
  const cv::Mat wide = Texture(cv::Size(size.width + 20, size.height), 11);
  const cv::Mat left = wide(cv::Rect(0, 0, size.width, size.height)).clone();
  const cv::Mat right = wide(cv::Rect(20, 0, size.width, size.height)).clone();
  const DisparityOptions o = DisparityOptions::ForWidth(size.width);  // 80 disparities
  ASSERT_EQ(o.num_disparities, 80);
  const cv::Mat1f d = ComputeDisparity(left, right, o);
  ASSERT_EQ(d.size(), size);
  // Valid region: columns >= num_disparities (the search needs them), away from the border.
  const cv::Mat1f inner = d(cv::Rect(85, 10, size.width - 95, size.height - 20));
  int valid = 0, right_value = 0;
  for (float v : inner) {
    valid += v > 0;
    right_value += std::abs(v - 20.0f) <= 0.25f;
  }
  EXPECT_GT(right_value, 0.95 * inner.total()) << valid << " valid";
  // The left band without a full search range is invalid: 0, never negative.
  double lo, hi;
  cv::minMaxLoc(d, &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_EQ(cv::countNonZero(d.colRange(0, 40)), 0);
  // Normalised: d / 80.
  const cv::Mat1f n = NormalizeDisparity(d, o);
  EXPECT_NEAR(n(80, 160), d(80, 160) / 80.0f, 1e-6);
}

TEST(ComputeDisparity, EurocPairsHaveAPlausibleDisparityMap) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const StereoCalibration c = LoadStereoCalibration(EurocCalibrationFile());
  const cv::Size size(752, 480);
  const StereoRectifier rectifier(c, size);
  const DisparityOptions o = DisparityOptions::ForWidth(size.width);
  const double fb = rectifier.Focal() * rectifier.Baseline();  // pixels x metres
  for (int i = 0; i < 4; ++i) {
    const StereoPair p = ProcessStereoPair(rectifier, o, EurocLeft(i), EurocRight(i));
    const cv::Mat1f& d = p.disparity;
    // Valid fraction over the part where a match can exist (right of the first 128 columns).
    const cv::Mat1f searchable = d.colRange(o.num_disparities, size.width);
    const double valid = static_cast<double>(cv::countNonZero(searchable)) / searchable.total();
    std::vector<float> values;
    for (float v : searchable)
      if (v > 0) values.push_back(v);
    std::sort(values.begin(), values.end());
    const float median = values[values.size() / 2];
    std::cout << "pair " << i << ": valid " << valid << " of the searchable area ("
              << static_cast<double>(cv::countNonZero(d)) / d.total() << " of the image), "
              << "median disparity " << median << " px = depth " << fb / median << " m, 5-95% "
              << values[values.size() / 20] << "-" << values[values.size() * 19 / 20]
              << " px (f*B = " << fb << ")\n";
    EXPECT_GT(valid, 0.4) << "pair " << i;
    EXPECT_LT(valid, 1.0) << "pair " << i;
    // The Vicon room of V1_01 is about 8 x 8 m: depths of the median pixel between 1 and 8 m,
    // and 95% of valid pixels farther than 0.4 m (depth = f B / d).
    EXPECT_GT(fb / median, 1.0) << "pair " << i;
    EXPECT_LT(fb / median, 8.0) << "pair " << i;
    EXPECT_LT(values[values.size() * 19 / 20], fb / 0.4) << "pair " << i;

    // Independent check: sparse ORB correspondences on the rectified pair (same row +-1 px)
    // give x_left - x_right; SGBM must agree at those pixels.
    const cv::Ptr<cv::ORB> orb = cv::ORB::create(2000);
    std::vector<cv::KeyPoint> kl, kr;
    cv::Mat dl, dr;
    orb->detectAndCompute(p.left_rectified, cv::noArray(), kl, dl);
    orb->detectAndCompute(p.right_rectified, cv::noArray(), kr, dr);
    std::vector<cv::DMatch> matches;
    cv::BFMatcher(cv::NORM_HAMMING, true).match(dl, dr, matches);
    std::vector<double> errors;
    for (const cv::DMatch& m : matches) {
      const cv::Point2f a = kl[m.queryIdx].pt, b = kr[m.trainIdx].pt;
      if (m.distance > 40 || std::abs(a.y - b.y) > 1.0f || a.x - b.x <= 0) continue;
      const float sgbm = d(cvRound(a.y), cvRound(a.x));
      if (sgbm > 0) errors.push_back(std::abs(sgbm - (a.x - b.x)));
    }
    ASSERT_GE(errors.size(), 30u) << "pair " << i;
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    std::cout << "  SGBM vs ORB disparity: median error " << errors[errors.size() / 2]
              << " px over " << errors.size() << " correspondences\n";
    EXPECT_LT(errors[errors.size() / 2], 1.0) << "pair " << i;
  }
}

}  // namespace
}  // namespace openable
