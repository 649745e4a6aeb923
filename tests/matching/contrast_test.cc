// SeqSLAM's local contrast enhancement (matching/contrast.h) against the definition computed
// cell by cell here.
#include "matching/contrast.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace openable {
namespace {

// D'(i, j) = (D(i, j) - mean) / std over the finite cells of row i in [j - R, j + R] within
// j's traversal (population std; 0 when the std is 0); then shifted by the smallest D'.
cv::Mat1f Naive(const cv::Mat1f& d, int window, const std::vector<int>& starts) {
  cv::Mat1f out = d.clone();
  float smallest = std::numeric_limits<float>::infinity();
  for (int i = 0; i < d.rows; ++i)
    for (int j = 0; j < d.cols; ++j) {
      if (!std::isfinite(d(i, j))) continue;
      int first = 0, end = d.cols;
      for (size_t t = 0; t < starts.size(); ++t)
        if (starts[t] <= j) first = starts[t], end = t + 1 < starts.size() ? starts[t + 1] : d.cols;
      double sum = 0, n = 0;
      for (int k = std::max(first, j - window); k < std::min(end, j + window + 1); ++k)
        if (std::isfinite(d(i, k))) sum += d(i, k), n += 1;
      const double mean = sum / n;
      double var = 0;
      for (int k = std::max(first, j - window); k < std::min(end, j + window + 1); ++k)
        if (std::isfinite(d(i, k))) var += (d(i, k) - mean) * (d(i, k) - mean);
      const double sd = std::sqrt(var / n);
      out(i, j) = sd > 1e-9 ? static_cast<float>((d(i, j) - mean) / sd) : 0.0f;
      smallest = std::min(smallest, out(i, j));
    }
  for (float& v : out)
    if (std::isfinite(v)) v -= smallest;
  return out;
}

TEST(ContrastEnhancement, HandWorkedRow) {
  // Row 1 2 3, window 1: cell 0 sees {1, 2}: (1 - 1.5) / 0.5 = -1; cell 1 sees {1, 2, 3}:
  // 0; cell 2 sees {2, 3}: +1. Shifted by -1: 0 1 2.
  cv::Mat1f d = (cv::Mat1f(1, 3) << 1, 2, 3);
  EnhanceContrast(d, 1);
  EXPECT_NEAR(d(0, 0), 0.0f, 1e-6);
  EXPECT_NEAR(d(0, 1), 1.0f, 1e-6);
  EXPECT_NEAR(d(0, 2), 2.0f, 1e-6);
}

TEST(ContrastEnhancement, MatchesTheDefinitionWithTraversalsAndEmptyCells) {
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> bits(0, 256), chance(0, 19);
  cv::Mat1f d(37, 90);
  for (float& v : d)
    v = chance(rng) == 0 ? std::numeric_limits<float>::infinity() : static_cast<float>(bits(rng));
  d.row(5).setTo(42.0f);                        // a uniform row: every cell 0 before the shift
  const std::vector<int> starts = {0, 40, 41};  // a one-frame traversal too
  for (int window : {1, 3, 10, 200})
    for (int threads : {1, 2, 3}) {
      cv::Mat1f got = d.clone();
      EnhanceContrast(got, window, starts, threads);
      const cv::Mat1f want = Naive(d, window, starts);
      for (int i = 0; i < d.rows; ++i)
        for (int j = 0; j < d.cols; ++j) {
          if (!std::isfinite(want(i, j))) {
            ASSERT_EQ(got(i, j), want(i, j)) << i << "," << j;
            continue;
          }
          ASSERT_NEAR(got(i, j), want(i, j), 1e-4) << "R=" << window << " at " << i << "," << j;
        }
      double lo = 0;
      cv::Mat1b finite = (d == d) & (d != std::numeric_limits<float>::infinity());
      cv::minMaxLoc(got, &lo, nullptr, nullptr, nullptr, finite);
      EXPECT_NEAR(lo, 0.0, 1e-6);  // shifted so that the smallest value is 0
    }
  cv::Mat1f bad = d.clone();
  EXPECT_THROW(EnhanceContrast(bad, 0), std::logic_error);
}

// Without the shift: every cell the same z-score, the smallest returned; and no z-score of a
// window of 2R + 1 values below -sqrt(2R) (Samuelson's inequality), the shift a map uses before
// it is tuned.
TEST(ContrastEnhancement, UnshiftedCellsAreTheShiftedOnesLessTheSmallest) {
  cv::Mat1f d(30, 41);
  cv::randu(d, 0.0f, 50.0f);
  d(3, 4) = std::numeric_limits<float>::infinity();
  cv::Mat1f shifted = d.clone(), unshifted = d.clone();
  EnhanceContrast(shifted, 5, {0, 20});
  const float smallest = EnhanceContrastUnshifted(unshifted, 5, {0, 20});
  EXPECT_LT(smallest, 0.0f);
  EXPECT_GE(smallest, -std::sqrt(2.0f * 5) - 1e-5f);
  for (int i = 0; i < d.rows; ++i)
    for (int j = 0; j < d.cols; ++j) {
      if (!std::isfinite(d(i, j))) {
        EXPECT_FALSE(std::isfinite(unshifted(i, j)));
        continue;
      }
      EXPECT_NEAR(unshifted(i, j) - smallest, shifted(i, j), 1e-5f) << i << ", " << j;
      EXPECT_GE(unshifted(i, j), -std::sqrt(2.0f * 5) - 1e-5f);
    }
  // The bound is reached by one value far below the others of its window.
  cv::Mat1f one = cv::Mat1f::ones(1, 11);
  one(0, 5) = -1000.0f;
  EnhanceContrastUnshifted(one, 5);
  EXPECT_NEAR(one(0, 5), -std::sqrt(10.0f), 1e-4f);
}

}  // namespace
}  // namespace openable
