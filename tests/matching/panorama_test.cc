#include "matching/panorama.h"

#include <gtest/gtest.h>

#include <bitset>
#include <cmath>
#include <random>

namespace openable {
namespace {

// Direct definitions (matching/panorama.h), one pair of rows at a time.
double StripDistance(const cv::Mat& rows, int i, int k, int j, int l, int w) {
  double s = 0;
  for (int e = 0; e < w; ++e) {
    if (rows.depth() == CV_8U) {
      s += std::bitset<8>(rows.at<std::uint8_t>(i, k * w + e) ^ rows.at<std::uint8_t>(j, l * w + e))
               .count();
    } else {
      const double d = rows.at<float>(i, k * w + e) - rows.at<float>(j, l * w + e);
      s += d * d;
    }
  }
  return rows.depth() == CV_8U ? s : std::sqrt(s);
}

double Naive(const cv::Mat& rows, int i, int j, int n, PanoramaMatching mode) {
  const int w = rows.cols / n;
  const bool binary = rows.depth() == CV_8U;
  auto shifted = [&](int s) {
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      const double d = StripDistance(rows, i, k, j, (k + s) % n, w);
      sum += binary ? d : d * d;
    }
    return binary ? sum : std::sqrt(sum);
  };
  if (mode == PanoramaMatching::kAligned) return shifted(0);
  double best = 1e300;
  for (int s = 0; s < n; ++s)
    if (mode == PanoramaMatching::kCircular) {
      best = std::min(best, shifted(s));
    } else {
      for (int l = 0; l < n; ++l) best = std::min(best, StripDistance(rows, i, s, j, l, w));
    }
  return best;
}

cv::Mat RandomRows(int rows, int cols, int type, unsigned seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  if (type == CV_8U) {
    rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  } else {
    rng.fill(m, cv::RNG::UNIFORM, -1.0, 1.0);
  }
  return m;
}

constexpr int kRows = 150;  // more than one task of rows, not a multiple of 4 or 16

class PanoramaDistancesTest
    : public ::testing::TestWithParam<std::tuple<int, PanoramaMatching, int>> {};

TEST_P(PanoramaDistancesTest, EqualsTheDirectDefinition) {
  const auto [type, mode, strips] = GetParam();
  const int w = type == CV_8U ? std::get<2>(GetParam()) * 0 + 32 : 5;  // 32 bytes: LDB
  const cv::Mat rows = RandomRows(kRows, strips * w, type, 7 + strips);
  std::int64_t last = 0;
  const cv::Mat1f m = PanoramaDistances(rows, strips, mode, 2,
                                        [&](std::int64_t done, std::int64_t) { last = done; });
  EXPECT_EQ(last, static_cast<std::int64_t>(kRows) * kRows *
                      (mode == PanoramaMatching::kAligned ? 1 : strips * strips));
  ASSERT_EQ(m.rows, kRows);
  ASSERT_EQ(m.cols, kRows);
  for (int i = 0; i < m.rows; ++i)
    for (int j = 0; j < m.cols; ++j)
      ASSERT_NEAR(m(i, j), Naive(rows, i, j, strips, mode), 1e-4 * (1 + std::fabs(m(i, j))))
          << "cell " << i << "," << j;
}

INSTANTIATE_TEST_SUITE_P(All, PanoramaDistancesTest,
                         ::testing::Combine(::testing::Values(CV_8U, CV_32F),
                                            ::testing::Values(PanoramaMatching::kAligned,
                                                              PanoramaMatching::kCrossCorrelation,
                                                              PanoramaMatching::kCircular),
                                            ::testing::Values(1, 2, 4, 5)));

// A row whose strips are turned by s strips is at distance 0 by cross-correlation and by the
// circular comparison, not by the aligned one.
TEST(PanoramaDistances, TurnedRowIsFoundByCrossCorrelationAndCircular) {
  const int n = 6, w = 4;
  cv::Mat rows = RandomRows(2, n * w, CV_8U, 3);
  for (int k = 0; k < n; ++k)
    rows.row(0)
        .colRange(((k + 2) % n) * w, ((k + 2) % n + 1) * w)
        .copyTo(rows.row(1).colRange(k * w, (k + 1) * w));
  EXPECT_EQ(PanoramaDistances(rows, n, PanoramaMatching::kCrossCorrelation)(1, 0), 0.0f);
  EXPECT_EQ(PanoramaDistances(rows, n, PanoramaMatching::kCircular)(1, 0), 0.0f);
  EXPECT_GT(PanoramaDistances(rows, n, PanoramaMatching::kAligned)(1, 0), 40.0f);
}

TEST(PanoramaDistances, RejectsWidthNotAMultipleOfStrips) {
  EXPECT_THROW(
      PanoramaDistances(cv::Mat(3, 10, CV_8U, cv::Scalar(0)), 3, PanoramaMatching::kCircular),
      std::invalid_argument);
  EXPECT_THROW(
      PanoramaDistances(cv::Mat(3, 10, CV_8U, cv::Scalar(0)), 0, PanoramaMatching::kCircular),
      std::invalid_argument);
}

}  // namespace
}  // namespace openable
