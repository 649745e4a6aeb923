#include "descriptors/freak.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "tests/descriptors/descriptor_test_util.h"

namespace openable {
namespace {

using namespace testing_util;  // NOLINT: the descriptor test helpers are this file's vocabulary

constexpr double kPi = 3.14159265358979323846;

// Mean of a field by brute force: every pixel whose centre lies in the disc, or the pixel under
// the field centre when none does.
double FieldMean(const cv::Mat& p, const FreakField& f) {
  long long sum = 0, n = 0;
  for (int y = 0; y < p.rows; ++y) {
    for (int x = 0; x < p.cols; ++x) {
      const double dx = x + 0.5 - f.x, dy = y + 0.5 - f.y;
      if (dx * dx + dy * dy <= f.radius * f.radius) {
        sum += p.at<std::uint8_t>(y, x);
        ++n;
      }
    }
  }
  if (n == 0) return p.at<std::uint8_t>(static_cast<int>(f.y), static_cast<int>(f.x));
  return static_cast<double>(sum) / static_cast<double>(n);
}

std::vector<int> ReferenceBits(const cv::Mat& p) {
  std::vector<double> means;
  for (const FreakField& f : FreakFields(p.rows)) means.push_back(FieldMean(p, f));
  std::vector<int> bits;
  for (const auto& pair : FreakPairs()) bits.push_back(means[pair[0]] > means[pair[1]] ? 1 : 0);
  return bits;
}

TEST(FreakTest, FieldsFollowTheDocumentedGeometry) {
  const int s = 64;
  const std::vector<FreakField> fields = FreakFields(s);
  ASSERT_EQ(fields.size(), 43u);
  // Computed here from the header's numbers: r_6 = (S/2) / 1.6, r_k = r_6 / 1.4^(6 - k),
  // rho = 0.6 r; fields 6 m .. 6 m + 5 are ring 6 - m at 60 j (+30 on odd m) degrees.
  const double r6 = 32.0 / 1.6;
  for (int m = 0; m < 7; ++m) {
    const int ring = 6 - m;
    const double r = r6 / std::pow(1.4, m);
    for (int j = 0; j < 6; ++j) {
      const FreakField& f = fields[6 * m + j];
      const double angle = (60.0 * j + (m % 2 == 1 ? 30.0 : 0.0)) * kPi / 180.0;
      EXPECT_EQ(f.ring, ring);
      EXPECT_NEAR(f.x, 32.0 + r * std::cos(angle), 1e-9) << 6 * m + j;
      EXPECT_NEAR(f.y, 32.0 - r * std::sin(angle), 1e-9) << 6 * m + j;
      EXPECT_NEAR(f.radius, 0.6 * r, 1e-9);
    }
  }
  EXPECT_EQ(fields[42].ring, -1);
  EXPECT_DOUBLE_EQ(fields[42].x, 32.0);
  EXPECT_DOUBLE_EQ(fields[42].y, 32.0);
  EXPECT_NEAR(fields[42].radius, fields[36].radius, 1e-12);
}

TEST(FreakTest, RingsGrowOverlapAndFitThePatch) {
  for (const int s : {16, 64, 100}) {
    const std::vector<FreakField> fields = FreakFields(s);
    double previous_r = 0.0, previous_rho = 0.0;
    for (int m = 6; m >= 0; --m) {  // innermost ring first
      const FreakField& f = fields[6 * m];
      const double r = std::hypot(f.x - s / 2.0, f.y - s / 2.0);
      EXPECT_GT(r, previous_r) << "ring radii must increase, size " << s;
      EXPECT_GT(f.radius, previous_rho) << "field sizes must increase, size " << s;
      previous_r = r;
      previous_rho = f.radius;
      // Neighbours on a ring overlap.
      const FreakField& g = fields[6 * m + 1];
      EXPECT_LT(std::hypot(f.x - g.x, f.y - g.y), f.radius + g.radius);
    }
    for (const FreakField& f : fields) {
      EXPECT_GE(f.x - f.radius, -1e-9);
      EXPECT_LE(f.x + f.radius, s + 1e-9);
      EXPECT_GE(f.y - f.radius, -1e-9);
      EXPECT_LE(f.y + f.radius, s + 1e-9);
    }
    // The outer ring reaches the border: rightmost field touches x = S.
    EXPECT_NEAR(fields[0].x + fields[0].radius, s, 1e-9);
  }
}

TEST(FreakTest, EveryFieldAveragesAtLeastOnePixel) {
  for (const int s : {16, 64}) {
    const FreakDescriptor d(Options(s));
    ASSERT_EQ(d.FieldPixelCounts().size(), 43u);
    for (const int n : d.FieldPixelCounts()) EXPECT_GE(n, 1);
    // At 64, an outer field (radius 12) holds about pi 12^2 = 452 pixels.
    if (s == 64) {
      EXPECT_NEAR(d.FieldPixelCounts()[0], kPi * 144.0, 30.0);
    }
  }
}

TEST(FreakTest, PairTableHas512DistinctPairsOfFields) {
  const auto& pairs = FreakPairs();
  std::set<std::pair<int, int>> seen;
  std::set<int> fields;
  for (const auto& p : pairs) {
    EXPECT_LT(p[0], p[1]);
    EXPECT_LT(p[1], 43);
    seen.insert({p[0], p[1]});
    fields.insert(p[0]);
    fields.insert(p[1]);
  }
  EXPECT_EQ(seen.size(), 512u);
  EXPECT_GT(fields.size(), 35u) << "the selection should use most fields";
}

TEST(FreakTest, BitsMatchABruteForceReference) {
  for (const int size : {16, 32, 64, 96}) {
    const FreakDescriptor d(Options(size));
    for (int seed = 0; seed < 3; ++seed) {
      const cv::Mat patch = TexturedPatch(size, 600 + seed);
      SCOPED_TRACE("size " + std::to_string(size) + " seed " + std::to_string(seed));
      const int ones = ExpectBitsAre(Describe(d, patch), ReferenceBits(patch));
      EXPECT_GT(ones, 50);  // neither all 0 nor all 1: the comparison is not vacuous
      EXPECT_LT(ones, 462);
    }
  }
}

TEST(FreakTest, AllPairBitsHoldsTheSelectedBits) {
  const FreakDescriptor d(Options(64));
  const cv::Mat patch = TexturedPatch(64, 42);
  const std::vector<std::uint8_t> all = d.AllPairBits(patch);
  ASSERT_EQ(all.size(), 903u);
  std::map<std::pair<int, int>, int> index;
  for (int i = 0, k = 0; i < 43; ++i)
    for (int j = i + 1; j < 43; ++j) index[{i, j}] = k++;
  const cv::Mat row = Describe(d, patch);
  for (int k = 0; k < 512; ++k) {
    const auto& p = FreakPairs()[k];
    EXPECT_EQ(Bit(row, k), all[index.at({p[0], p[1]})]) << k;
  }
}

TEST(FreakTest, BrightLeftDarkRightGivesTheBitsTheGeometryPredicts) {
  // A field wholly left of x = 32 has mean 200, wholly right 50: bit (a, b) = 1 when a is left
  // and b right, 0 when a is right and b left or both are on the same side.
  const cv::Mat patch = BrightLeftDarkRightPatch();
  const FreakDescriptor d(Options(64));
  const std::vector<FreakField> fields = FreakFields(64);
  const auto half = [](const FreakField& f) {
    return f.x + f.radius < 32   ? Half::kLeft
           : f.x - f.radius > 32 ? Half::kRight
                                 : Half::kStraddles;
  };
  const DecidedBits count = ExpectBitsDecidedByHalves(
      Describe(d, patch), 512,
      [&](int k) {
        return std::make_pair(half(fields[FreakPairs()[k][0]]), half(fields[FreakPairs()[k][1]]));
      },
      {Half::kLeft, Half::kRight});
  EXPECT_GT(count.decided, 100);
  EXPECT_GT(count.ones, 10);
  // Field 3 (left, 180 degrees) against field 0 (right) on the outer ring, by hand.
  const std::vector<std::uint8_t> all = d.AllPairBits(patch);
  EXPECT_EQ(all[0 * 42 + (3 - 1)], 0);   // pair (0, 3): mean(right) > mean(left) is false
  EXPECT_EQ(all[0 * 42 + (42 - 1)], 0);  // pair (0, 42): right against the centre (straddles)
}

TEST(FreakTest, UniformPatchGivesZeros) {
  const FreakDescriptor d(Options(64));
  EXPECT_EQ(cv::countNonZero(Describe(d, cv::Mat(64, 64, CV_8UC1, cv::Scalar(200)))), 0);
}

TEST(FreakTest, SmallNoiseChangesFewBitsAndOtherImagesAboutHalf) {
  // Noise changes fewer than 10% of the 512 bits, an unrelated patch about half of them.
  ExpectNoisyCloseAndOtherFar(FreakDescriptor(Options(64)), 77, 810, 910, {51, 180, 332});
}

}  // namespace
}  // namespace openable
