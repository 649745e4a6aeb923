#include "OpenABLE/snaps/quality_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>

namespace openable::snaps {
namespace {

cv::Mat1b RandomImage(int rows, int cols, int seed) {
  cv::Mat1b m(rows, cols);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

// Eq. 4-5 on one window, two passes, written independently of the library.
double WindowQ(const cv::Mat1d& x, const cv::Mat1d& y, int r0, int c0, int b) {
  const double n = b * b;
  double mx = 0, my = 0;
  for (int r = r0; r < r0 + b; ++r)
    for (int c = c0; c < c0 + b; ++c) {
      mx += x(r, c);
      my += y(r, c);
    }
  mx /= n;
  my /= n;
  double vx = 0, vy = 0, cxy = 0;
  for (int r = r0; r < r0 + b; ++r)
    for (int c = c0; c < c0 + b; ++c) {
      vx += (x(r, c) - mx) * (x(r, c) - mx);
      vy += (y(r, c) - my) * (y(r, c) - my);
      cxy += (x(r, c) - mx) * (y(r, c) - my);
    }
  vx /= n - 1;
  vy /= n - 1;
  cxy /= n - 1;
  return 4 * cxy * mx * my / ((vx + vy) * (mx * mx + my * my));
}

TEST(QualityIndex, IdenticalImagesGiveExactlyOne) {
  const cv::Mat1b x = RandomImage(31, 103, 1);
  EXPECT_EQ(UniversalQualityIndex(x, x, 8), 1.0);
  cv::Mat1f f;
  x.convertTo(f, CV_32F, 1.0 / 255);
  EXPECT_EQ(UniversalQualityIndex(f, f.clone(), 8), 1.0);
}

TEST(QualityIndex, OneWindowByHand) {
  // x = [1 2; 3 4], y = [2 2; 5 3], one 2x2 window.
  // mean x = 2.5, mean y = 3; deviations x: -1.5 -0.5 0.5 1.5, y: -1 -1 2 0.
  // var x = (2.25 + 0.25 + 0.25 + 2.25) / 3 = 5/3; var y = (1 + 1 + 4 + 0) / 3 = 2;
  // cov = (1.5 + 0.5 + 1 + 0) / 3 = 1.
  // Q = 4 * 1 * 2.5 * 3 / ((5/3 + 2) * (6.25 + 9)) = 30 / (11/3 * 15.25) = 90 / 167.75.
  const cv::Mat1b x = (cv::Mat1b(2, 2) << 1, 2, 3, 4);
  const cv::Mat1b y = (cv::Mat1b(2, 2) << 2, 2, 5, 3);
  EXPECT_NEAR(UniversalQualityIndex(x, y, 2), 90.0 / 167.75, 1e-15);
}

TEST(QualityIndex, MeanOfAllSlidingWindowsAsBruteForce) {
  const cv::Mat1b xb = RandomImage(12, 15, 2), yb = RandomImage(12, 15, 3);
  cv::Mat1d x, y;
  xb.convertTo(x, CV_64F);
  // y correlated with x so that Q is far from 0.
  cv::Mat1d noise;
  yb.convertTo(noise, CV_64F);
  y = 0.7 * x + 0.3 * noise;
  cv::Mat1b y8;
  y.convertTo(y8, CV_8U);
  y8.convertTo(y, CV_64F);
  for (const int b : {2, 4, 8, 12}) {
    double sum = 0;
    int count = 0;
    for (int r = 0; r + b <= 12; ++r)
      for (int c = 0; c + b <= 15; ++c, ++count) sum += WindowQ(x, y, r, c, b);
    EXPECT_NEAR(UniversalQualityIndex(xb, y8, b), sum / count, 1e-12) << "B = " << b;
  }
  EXPECT_GT(UniversalQualityIndex(xb, y8, 4), 0.3);
}

TEST(QualityIndex, ConstantOffsetCostsTheLuminanceTerm) {
  const cv::Mat1b x = RandomImage(8, 8, 4) / 2;  // values 0..127
  const cv::Mat1b y = x + 40;
  const double mx = cv::mean(x)[0], my = mx + 40;
  EXPECT_NEAR(UniversalQualityIndex(x, y, 8), 2 * mx * my / (mx * mx + my * my), 1e-12);
  EXPECT_LT(UniversalQualityIndex(x, y, 8), 1.0);
}

TEST(QualityIndex, ContrastChangeCostsTheContrastTerm) {
  cv::Mat1d x(6, 6);
  cv::RNG rng(5);
  rng.fill(x, cv::RNG::UNIFORM, 0.2, 0.8);
  const double mean = cv::mean(x)[0];
  for (const double a : {0.5, 2.0, 3.0}) {
    const cv::Mat1d y = a * (x - mean) + mean;  // same mean, sigma_y = a sigma_x, correlation 1
    EXPECT_NEAR(UniversalQualityIndex(x, y, 6), 2 * a / (1 + a * a), 1e-12) << a;
  }
}

TEST(QualityIndex, Symmetric) {
  const cv::Mat1b x = RandomImage(20, 25, 6), y = RandomImage(20, 25, 7);
  EXPECT_DOUBLE_EQ(UniversalQualityIndex(x, y, 5), UniversalQualityIndex(y, x, 5));
}

TEST(QualityIndex, ZeroDenominatorRule) {
  const cv::Mat1b a(4, 4, uchar{100}), b(4, 4, uchar{50}), zero(4, 4, uchar{0});
  EXPECT_EQ(UniversalQualityIndex(a, a, 4), 1.0);
  EXPECT_EQ(UniversalQualityIndex(zero, zero, 4), 1.0);
  EXPECT_NEAR(UniversalQualityIndex(a, b, 4), 2.0 * 100 * 50 / (100 * 100 + 50 * 50), 1e-15);
  cv::Mat1b c = a.clone();
  c(0, 0) = 10;
  EXPECT_EQ(UniversalQualityIndex(a, c, 4), 0.0);  // one constant window: covariance 0
}

TEST(QualityIndex, Errors) {
  const cv::Mat1b x(10, 12, uchar{1});
  EXPECT_THROW(UniversalQualityIndex(x, cv::Mat1b(10, 11, uchar{1}), 4), std::invalid_argument);
  EXPECT_THROW(UniversalQualityIndex(x, x, 11), std::invalid_argument);
  EXPECT_THROW(UniversalQualityIndex(x, x, 0), std::invalid_argument);
  EXPECT_THROW(UniversalQualityIndex(cv::Mat3b(10, 12), cv::Mat3b(10, 12), 4),
               std::invalid_argument);
  EXPECT_THROW(UniversalQualityIndex(cv::Mat(), cv::Mat(), 1), std::invalid_argument);
}

TEST(Thumbnail, AreaAverageAtOneSixth) {
  cv::Mat1b frame(6, 12);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 12; ++c) frame(r, c) = static_cast<uchar>(c < 6 ? 10 + r : 200 - c);
  const cv::Mat t = Thumbnail(frame);
  ASSERT_EQ(t.size(), cv::Size(2, 1));
  ASSERT_EQ(t.type(), CV_8UC1);
  // Block means: rows 10..15 -> 12.5; columns 200-6..200-11 -> 191.5 (rounded either way).
  EXPECT_NEAR(t.at<uchar>(0, 0), 12.5, 0.5);
  EXPECT_NEAR(t.at<uchar>(0, 1), 191.5, 0.5);
  EXPECT_EQ(Thumbnail(cv::Mat1b(188, 620)).size(), cv::Size(103, 31));
  EXPECT_THROW(Thumbnail(frame, 0), std::invalid_argument);
  EXPECT_THROW(Thumbnail(frame, 1.5), std::invalid_argument);
}

}  // namespace
}  // namespace openable::snaps
