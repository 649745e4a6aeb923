#include "descriptors/brief.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "tests/descriptors/descriptor_test_util.h"

namespace openable {
namespace {

using namespace testing_util;  // NOLINT: the descriptor test helpers are this file's vocabulary

// The pattern's pixel position of a unit offset, from the header's formula.
int Pixel(double z, int s) {
  const int v = static_cast<int>(std::floor(s / 2.0 + z * s / 5.0));
  return std::min(std::max(v, 0), s - 1);
}

// Box mean around (col, row) clipped to the patch, by a plain pixel loop.
double BoxMean(const cv::Mat& p, int col, int row, int h) {
  long long sum = 0, n = 0;
  for (int y = row - h; y <= row + h; ++y) {
    for (int x = col - h; x <= col + h; ++x) {
      if (x < 0 || y < 0 || x >= p.cols || y >= p.rows) continue;
      sum += p.at<std::uint8_t>(y, x);
      ++n;
    }
  }
  return static_cast<double>(sum) / static_cast<double>(n);
}

// The 256 bits from the specification: unit pattern -> pixels -> brute-force box means.
std::vector<int> ReferenceBits(const cv::Mat& p) {
  const int s = p.rows;
  const int h = std::max(1, static_cast<int>(std::lround(s / 12.0)));  // 4 S / 48
  std::vector<int> bits;
  for (const BriefUnitTest& t : BriefUnitPattern()) {
    const double mx = BoxMean(p, Pixel(t.x_col, s), Pixel(t.x_row, s), h);
    const double my = BoxMean(p, Pixel(t.y_col, s), Pixel(t.y_row, s), h);
    bits.push_back(mx < my ? 1 : 0);
  }
  return bits;
}

TEST(BriefTest, UnitPatternIsBoxMullerOnRawMt19937Outputs) {
  // Recomputed here from the documented recipe (the header), independently of the library.
  constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
  std::mt19937 g(0x42524945u);
  const auto normal_pair = [&g](double* z0, double* z1) {
    const double a = static_cast<double>(g()), b = static_cast<double>(g());
    const double u1 = (a + 0.5) / 4294967296.0, u2 = (b + 0.5) / 4294967296.0;
    const double r = std::sqrt(-2.0 * std::log(u1));
    *z0 = r * std::cos(kTwoPi * u2);
    *z1 = r * std::sin(kTwoPi * u2);
  };
  for (const BriefUnitTest& t : BriefUnitPattern()) {
    double xc, xr, yc, yr;
    normal_pair(&xc, &xr);
    normal_pair(&yc, &yr);
    EXPECT_NEAR(t.x_col, xc, 1e-12);
    EXPECT_NEAR(t.x_row, xr, 1e-12);
    EXPECT_NEAR(t.y_col, yc, 1e-12);
    EXPECT_NEAR(t.y_row, yr, 1e-12);
  }
}

TEST(BriefTest, UnitPatternIsStandardNormal) {
  // 1024 deviates: mean 0 (standard error 0.031), standard deviation 1 (standard error 0.022).
  std::vector<double> z;
  for (const BriefUnitTest& t : BriefUnitPattern()) {
    z.insert(z.end(), {t.x_col, t.x_row, t.y_col, t.y_row});
  }
  double sum = 0, sq = 0;
  for (const double v : z) sum += v;
  const double mean = sum / z.size();
  for (const double v : z) sq += (v - mean) * (v - mean);
  const double sd = std::sqrt(sq / (z.size() - 1));
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(sd, 1.0, 0.07);
  // About 5% of |z| above 1.96, 0.3% above 3.
  const auto beyond = [&z](double limit) {
    return static_cast<double>(std::count_if(z.begin(), z.end(),
                                             [limit](double v) { return std::abs(v) > limit; })) /
           z.size();
  };
  EXPECT_NEAR(beyond(1.96), 0.05, 0.02);
  EXPECT_LT(beyond(3.0), 0.012);
}

TEST(BriefTest, PixelPatternAt64HasSigmaSOver5AndStaysInThePatch) {
  const BriefDescriptor d(Options(64));
  ASSERT_EQ(d.PixelTests().size(), 256u);
  std::vector<int> coords;
  int on_border = 0;
  for (const BriefPixelTest& t : d.PixelTests()) {
    for (const int v : {t.x_col, t.x_row, t.y_col, t.y_row}) {
      EXPECT_GE(v, 0);
      EXPECT_LE(v, 63);
      coords.push_back(v);
      if (v == 0 || v == 63) ++on_border;
    }
  }
  double sum = 0, sq = 0;
  for (const int v : coords) sum += v;
  const double mean = sum / coords.size();
  for (const int v : coords) sq += (v - mean) * (v - mean);
  const double sd = std::sqrt(sq / (coords.size() - 1));
  EXPECT_NEAR(mean, 31.5, 1.5);                // pixel centre of the patch
  EXPECT_NEAR(sd, 64.0 / 5.0, 1.2);            // sigma = S / 5 (clipping lowers it slightly)
  EXPECT_LT(on_border, 0.04 * coords.size());  // P(|z| > 2.5) = 1.2% per coordinate
}

TEST(BriefTest, PatternScalesWithThePatch) {
  EXPECT_EQ(BriefDescriptor(Options(16)).BoxHalfSide(), 1);
  EXPECT_EQ(BriefDescriptor(Options(48)).BoxHalfSide(), 4);  // the paper's 9 x 9 at S = 48
  EXPECT_EQ(BriefDescriptor(Options(64)).BoxHalfSide(), 5);
  const BriefDescriptor small(Options(32)), large(Options(64));
  int close = 0;
  for (int k = 0; k < 256; ++k) {
    const BriefPixelTest& a = small.PixelTests()[k];
    const BriefPixelTest& b = large.PixelTests()[k];
    // Same unit pattern: positions at 64 are about twice those at 32 (up to rounding, clipping).
    if (std::abs(2 * a.x_col - b.x_col) <= 2 && std::abs(2 * a.y_row - b.y_row) <= 2) ++close;
  }
  EXPECT_GT(close, 240);
}

TEST(BriefTest, BitsMatchABruteForceReference) {
  for (const int size : {16, 32, 64, 96}) {
    const BriefDescriptor d(Options(size));
    for (int seed = 0; seed < 4; ++seed) {
      const cv::Mat patch = TexturedPatch(size, 700 + seed);
      SCOPED_TRACE("size " + std::to_string(size) + " seed " + std::to_string(seed));
      const int ones = ExpectBitsAre(Describe(d, patch), ReferenceBits(patch));
      EXPECT_GT(ones, 60);
      EXPECT_LT(ones, 196);
    }
  }
}

TEST(BriefTest, BrightLeftDarkRightGivesTheBitsTheGeometryPredicts) {
  // A box wholly on the left has mean 200, wholly on the right 50: bit = 1 when x is right and
  // y left, 0 when x is left and y right or both boxes are on the same side (equal means).
  const BriefDescriptor d(Options(64));
  const int h = d.BoxHalfSide();
  const auto half = [h](int col) {
    return col + h < 32 ? Half::kLeft : col - h >= 32 ? Half::kRight : Half::kStraddles;
  };
  const auto halves = [&](int k) {
    const BriefPixelTest& t = d.PixelTests()[k];
    return std::make_pair(half(t.x_col), half(t.y_col));
  };
  const DecidedBits count = ExpectBitsDecidedByHalves(Describe(d, BrightLeftDarkRightPatch()), 256,
                                                      halves, {Half::kRight, Half::kLeft});
  EXPECT_GT(count.decided, 60);
  EXPECT_GT(count.ones, 10);
}

TEST(BriefTest, UniformPatchGivesZeros) {
  const BriefDescriptor d(Options(64));
  EXPECT_EQ(cv::countNonZero(Describe(d, cv::Mat(64, 64, CV_8UC1, cv::Scalar(90)))), 0);
}

TEST(BriefTest, SmallNoiseChangesFewBitsAndOtherImagesAboutHalf) {
  // Noise changes fewer than 10% of the 256 bits, an unrelated patch about half of them.
  ExpectNoisyCloseAndOtherFar(BriefDescriptor(Options(64)), 99, 800, 900, {26, 90, 166});
}

}  // namespace
}  // namespace openable
