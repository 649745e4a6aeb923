#include "descriptors/ldb.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/descriptors/descriptor_test_util.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace testing_util;  // NOLINT: the descriptor test helpers are this file's vocabulary

constexpr int kLevels[] = {2, 3, 4, 5};
enum Feature { kI = 0, kGx = 1, kGy = 2 };

// Index of test (level n, cells i < j, feature) in the canonical order, counted independently.
int CanonicalIndex(int n, int i, int j, int feature) {
  int index = 0;
  for (const int m : kLevels) {
    if (m == n) break;
    index += 3 * (m * m) * (m * m - 1) / 2;
  }
  int pair = 0;
  for (int a = 0; a < i; ++a) pair += n * n - 1 - a;
  pair += j - i - 1;
  return index + 3 * pair + feature;
}

// The 1386 canonical bits, from the specification with plain pixel loops (no integral image).
std::vector<int> ReferenceBits(const cv::Mat& p) {
  const int s = p.rows;
  const auto mean = [&p](int y0, int y1, int x0, int x1) {
    long long sum = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) sum += p.at<std::uint8_t>(y, x);
    return static_cast<double>(sum) / (static_cast<double>(y1 - y0) * (x1 - x0));
  };
  std::vector<int> bits;
  for (const int n : kLevels) {
    std::vector<std::array<double, 3>> f;
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        const int y0 = r * s / n, y1 = (r + 1) * s / n, x0 = c * s / n, x1 = (c + 1) * s / n;
        const int xm = (x0 + x1) / 2, ym = (y0 + y1) / 2;
        f.push_back({mean(y0, y1, x0, x1), mean(y0, y1, xm, x1) - mean(y0, y1, x0, xm),
                     mean(ym, y1, x0, x1) - mean(y0, ym, x0, x1)});
      }
    }
    for (int i = 0; i < n * n; ++i)
      for (int j = i + 1; j < n * n; ++j)
        for (int k = 0; k < 3; ++k) bits.push_back(f[i][k] < f[j][k] ? 1 : 0);
  }
  return bits;
}

std::vector<int> AllBits(const cv::Mat& row, int count) {
  std::vector<int> bits;
  for (int k = 0; k < count; ++k) bits.push_back(Bit(row, k));
  return bits;
}

cv::Mat FromFunction(int size, int (*value)(int y, int x)) {
  cv::Mat p(size, size, CV_8UC1);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      p.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(value(y, x));
  return p;
}

// The full canonical descriptor (1386 bits keep every test in canonical order).
std::vector<int> FullBits(const cv::Mat& patch) {
  const LdbDescriptor full(Options(patch.rows, kLdbTotalTests));
  return AllBits(Describe(full, patch), kLdbTotalTests);
}

// ---------------------------------------------------------------------------------------------

TEST(LdbTest, CanonicalIndexHelperCoversEveryTest) {
  EXPECT_EQ(CanonicalIndex(2, 0, 1, kI), 0);
  EXPECT_EQ(CanonicalIndex(2, 2, 3, kGy), 17);
  EXPECT_EQ(CanonicalIndex(3, 0, 1, kI), 18);
  EXPECT_EQ(CanonicalIndex(5, 23, 24, kGy), kLdbTotalTests - 1);
}

TEST(LdbTest, WidthIsCeilOfBitsOverEight) {
  EXPECT_EQ(LdbDescriptor(Options(64, 256)).Width(), 32);
  EXPECT_EQ(LdbDescriptor(Options(64, 1386)).Width(), 174);
  EXPECT_EQ(LdbDescriptor(Options(64, 1)).Width(), 1);
  EXPECT_EQ(LdbDescriptor(Options(64, 100)).Width(), 13);
  EXPECT_EQ(LdbDescriptor(Options(64, 255)).Width(), 32);
  EXPECT_EQ(LdbDescriptor(Options(64, 257)).Width(), 33);
}

TEST(LdbTest, PaddingBitsAreZero) {
  for (const int bits : {1, 3, 100, 255, 1386}) {
    for (const LdbSelection selection : {LdbSelection::kRandom, LdbSelection::kCoarseFirst}) {
      const LdbDescriptor d(Options(64, bits), selection);
      int ones = 0;
      for (int seed = 0; seed < 8; ++seed) {
        const cv::Mat row = Describe(d, TexturedPatch(64, 500 + seed));
        for (int k = bits; k < 8 * d.Width(); ++k) EXPECT_EQ(Bit(row, k), 0) << bits << " " << k;
        for (int k = 0; k < bits; ++k) ones += Bit(row, k);
      }
      if (bits >= 100) {
        EXPECT_GT(ones, 0);  // the test would be empty otherwise
      }
    }
  }
}

TEST(LdbTest, SelectionIsADeterministicSubsetWithoutDuplicates) {
  for (const LdbSelection selection : {LdbSelection::kRandom, LdbSelection::kCoarseFirst}) {
    for (const int bits : {1, 17, 256, 1000, 1385, 1386}) {
      const std::vector<int> tests = LdbSelectedTests(bits, selection);
      ASSERT_EQ(static_cast<int>(tests.size()), bits);
      const std::set<int> unique(tests.begin(), tests.end());
      EXPECT_EQ(static_cast<int>(unique.size()), bits) << "duplicates at " << bits;
      EXPECT_GE(*unique.begin(), 0);
      EXPECT_LT(*unique.rbegin(), kLdbTotalTests);
      EXPECT_EQ(tests, LdbSelectedTests(bits, selection));
    }
  }
  EXPECT_THROW(LdbSelectedTests(0, LdbSelection::kRandom), std::logic_error);
  EXPECT_THROW(LdbSelectedTests(1387, LdbSelection::kCoarseFirst), std::logic_error);
}

TEST(LdbTest, FullLengthKeepsCanonicalOrderAndCoarseFirstIsAPrefix) {
  for (const LdbSelection selection : {LdbSelection::kRandom, LdbSelection::kCoarseFirst}) {
    const std::vector<int> all = LdbSelectedTests(kLdbTotalTests, selection);
    for (int k = 0; k < kLdbTotalTests; ++k) ASSERT_EQ(all[k], k);
  }
  const std::vector<int> coarse = LdbSelectedTests(300, LdbSelection::kCoarseFirst);
  for (int k = 0; k < 300; ++k) EXPECT_EQ(coarse[k], k);
}

TEST(LdbTest, RandomSelectionIsTheDocumentedFisherYatesShuffle) {
  // Re-derived from the header's description: Fisher-Yates on raw mt19937 outputs.
  std::vector<int> order(kLdbTotalTests);
  for (int i = 0; i < kLdbTotalTests; ++i) order[i] = i;
  std::mt19937 generator(0x4C4442u);
  for (int i = kLdbTotalTests - 1; i >= 1; --i) {
    const std::uint32_t j =
        static_cast<std::uint32_t>(generator()) % static_cast<std::uint32_t>(i + 1);
    std::swap(order[i], order[j]);
  }
  const std::vector<int> selected = LdbSelectedTests(256, LdbSelection::kRandom);
  EXPECT_EQ(selected, std::vector<int>(order.begin(), order.begin() + 256));
  // A shorter selection is a prefix of a longer one.
  const std::vector<int> longer = LdbSelectedTests(1000, LdbSelection::kRandom);
  EXPECT_EQ(selected, std::vector<int>(longer.begin(), longer.begin() + 256));
  // It mixes the levels and the three features.
  std::set<int> levels, features;
  for (const int t : selected) {
    features.insert(t % 3);
    levels.insert(t < 18 ? 2 : t < 126 ? 3 : t < 486 ? 4 : 5);
  }
  EXPECT_EQ(levels.size(), 4u);
  EXPECT_EQ(features.size(), 3u);
}

TEST(LdbTest, MatchesIndependentReferenceOnTexturedPatches) {
  for (const int size : {16, 37, 64, 100}) {
    for (int seed = 0; seed < 3; ++seed) {
      const cv::Mat patch = TexturedPatch(size, 900 + 10 * size + seed);
      EXPECT_EQ(FullBits(patch), ReferenceBits(patch)) << "size " << size << " seed " << seed;
    }
  }
  // White noise: cells of very different content.
  cv::Mat noise(41, 41, CV_8UC1);
  cv::RNG(77).fill(noise, cv::RNG::UNIFORM, 0, 256);
  EXPECT_EQ(FullBits(noise), ReferenceBits(noise));
}

TEST(LdbTest, SelectedBitsAreTheFullDescriptorBitsAtTheSelectedTests) {
  const cv::Mat patch = TexturedPatch(64, 31);
  const std::vector<int> full = FullBits(patch);
  for (const LdbSelection selection : {LdbSelection::kRandom, LdbSelection::kCoarseFirst}) {
    for (const int bits : {256, 77}) {
      const LdbDescriptor d(Options(64, bits), selection);
      const cv::Mat row = Describe(d, patch);
      const std::vector<int> tests = LdbSelectedTests(bits, selection);
      EXPECT_EQ(d.SelectedTests(), tests);
      for (int k = 0; k < bits; ++k) EXPECT_EQ(Bit(row, k), full[tests[k]]) << "bit " << k;
    }
  }
}

// Expects the 18 bits of level 2: the I bits of the cell pairs (0,1) (0,2) (0,3) (1,2) (1,3)
// (2,3) as given, every G_x and G_y bit 0.
void ExpectLevel2(const std::vector<int>& bits, const std::array<int, 6>& intensity) {
  std::vector<int> expected;
  for (const int i : intensity) expected.insert(expected.end(), {i, 0, 0});
  EXPECT_EQ(std::vector<int>(bits.begin(), bits.begin() + 18), expected);
}

// Whether the level-3 bit of one feature is 1 for the cells i < j.
using PairRule = bool (*)(int i, int j);
bool Never(int /*i*/, int /*j*/) { return false; }

// Expects every bit of level 3 to follow the rules of I, G_x and G_y.
void ExpectLevel3(const std::vector<int>& bits, PairRule intensity, PairRule gx, PairRule gy) {
  const PairRule rules[] = {intensity, gx, gy};
  for (int i = 0; i < 9; ++i) {
    for (int j = i + 1; j < 9; ++j) {
      for (const Feature f : {kI, kGx, kGy}) {
        EXPECT_EQ(bits[CanonicalIndex(3, i, j, f)], rules[f](i, j) ? 1 : 0)
            << i << "," << j << " feature " << f;
      }
    }
  }
}

// Left half (columns 0..31) dark, right half bright.
int LeftDarkRightBright(int /*y*/, int x) { return x < 32 ? 0 : 200; }

TEST(LdbTest, HandComputedBitsOfAVerticalEdge) {
  const std::vector<int> bits = FullBits(FromFunction(64, LeftDarkRightBright));
  // Level 2: cells 0, 2 dark, 1, 3 bright; every cell uniform, so G_x = G_y = 0 everywhere.
  // I bit of (i, j) = 1 iff I(i) < I(j): (0,1) 0 < 200, (0,3), (2,3).
  ExpectLevel2(bits, {1, 0, 1, 0, 0, 1});

  // Level 3: columns [0,21) all dark; [21,42) has 11 dark and 10 bright columns:
  // I = 200 * 10 / 21 = 95.2, halves [21,31) dark and [31,42) 1 dark + 10 bright, so
  // G_x = 2000 / 11 = 181.8; [42,64) all bright. G_y = 0 (columns are constant).
  EXPECT_EQ(bits[CanonicalIndex(3, 0, 1, kI)], 1);   // 0 < 95.2
  EXPECT_EQ(bits[CanonicalIndex(3, 0, 1, kGx)], 1);  // 0 < 181.8
  EXPECT_EQ(bits[CanonicalIndex(3, 0, 1, kGy)], 0);
  EXPECT_EQ(bits[CanonicalIndex(3, 1, 2, kI)], 1);   // 95.2 < 200
  EXPECT_EQ(bits[CanonicalIndex(3, 1, 2, kGx)], 0);  // 181.8 > 0
  EXPECT_EQ(bits[CanonicalIndex(3, 1, 4, kI)], 0);   // same column: equal
  EXPECT_EQ(bits[CanonicalIndex(3, 1, 4, kGx)], 0);  // equal (2000/11 for 21 and 21 rows)
  EXPECT_EQ(bits[CanonicalIndex(3, 2, 4, kI)], 0);   // 200 > 95.2
  EXPECT_EQ(bits[CanonicalIndex(3, 2, 4, kGx)], 1);  // 0 < 181.8
  EXPECT_EQ(bits[CanonicalIndex(3, 4, 7, kGx)], 0);  // rows of 21 and 22: still 2000/11
  EXPECT_EQ(bits[CanonicalIndex(3, 6, 8, kI)], 1);   // 0 < 200
  // The whole of level 3 follows from the column means: I bit iff col(i) < col(j);
  // G_x bit iff col(j) is the middle column and col(i) is not.
  ExpectLevel3(
      bits, [](int i, int j) { return i % 3 < j % 3; },
      [](int i, int j) { return j % 3 == 1 && i % 3 != 1; }, Never);
}

int VerticalRamp(int y, int /*x*/) { return 4 * y; }
int HorizontalRamp(int /*y*/, int x) { return 4 * x; }

TEST(LdbTest, HandComputedBitsOfAVerticalRamp) {
  const std::vector<int> bits = FullBits(FromFunction(64, VerticalRamp));
  // Level 2: top cells 0, 1 have I = 4 * 15.5 = 62, bottom cells 2, 3 have 190; every cell is
  // 32 rows high so G_y = 4 * 16 = 64 everywhere (ties give 0); G_x = 0.
  ExpectLevel2(bits, {0, 1, 1, 1, 1, 0});
  // Level 3: rows [0,21) and [21,42) split 10 + 11 rows, G_y = 4 * 10.5 = 42; rows [42,64)
  // split 11 + 11, G_y = 4 * 11 = 44. So the G_y bit is 1 iff j is in the last row and i is not.
  EXPECT_EQ(bits[CanonicalIndex(3, 0, 6, kGy)], 1);  // 42 < 44
  EXPECT_EQ(bits[CanonicalIndex(3, 4, 8, kGy)], 1);  // 42 < 44
  EXPECT_EQ(bits[CanonicalIndex(3, 0, 3, kGy)], 0);  // 42 = 42
  EXPECT_EQ(bits[CanonicalIndex(3, 6, 7, kGy)], 0);  // 44 = 44
  ExpectLevel3(
      bits, [](int i, int j) { return i / 3 < j / 3; }, Never,
      [](int i, int j) { return j / 3 == 2 && i / 3 != 2; });
}

TEST(LdbTest, HandComputedBitsOfAHorizontalRamp) {
  // The transpose of the vertical ramp: the roles of G_x and G_y swap.
  const std::vector<int> bits = FullBits(FromFunction(64, HorizontalRamp));
  ExpectLevel2(bits, {1, 0, 1, 0, 0, 1});  // (0,1): 62 < 190
  ExpectLevel3(
      bits, [](int i, int j) { return i % 3 < j % 3; },
      [](int i, int j) { return j % 3 == 2 && i % 3 != 2; }, Never);
}

TEST(LdbTest, UniformPatchHasNoBitsSet) {
  // Every feature ties, and a tie gives 0 (Eq. 1).
  for (const int value : {0, 128, 255}) {
    const std::vector<int> bits = FullBits(cv::Mat(64, 64, CV_8UC1, cv::Scalar(value)));
    for (int k = 0; k < kLdbTotalTests; ++k) ASSERT_EQ(bits[k], 0) << value << " bit " << k;
  }
}

TEST(LdbTest, DistanceGrowsWithNoise) {
  const LdbDescriptor d(Options(64, 256));
  const std::vector<double> sigmas = {5.0, 20.0, 60.0};
  std::vector<double> mean_distance(sigmas.size(), 0.0);
  constexpr int kPatches = 4;
  constexpr int kNoiseSeeds = 4;
  for (int p = 0; p < kPatches; ++p) {
    const cv::Mat patch = TexturedPatch(64, 1000 + p);
    const cv::Mat original = Describe(d, patch);
    for (std::size_t s = 0; s < sigmas.size(); ++s) {
      for (int n = 0; n < kNoiseSeeds; ++n) {
        cv::Mat noise(64, 64, CV_32F);
        cv::RNG(2000 + 17 * p + n).fill(noise, cv::RNG::NORMAL, 0.0, sigmas[s]);
        cv::Mat noisy;
        patch.convertTo(noisy, CV_32F);
        noisy += noise;
        noisy.convertTo(noisy, CV_8U);  // saturates to [0, 255]
        mean_distance[s] += Hamming(original, Describe(d, noisy));
      }
    }
  }
  for (double& m : mean_distance) m /= kPatches * kNoiseSeeds;
  EXPECT_LE(mean_distance[0], mean_distance[1]);
  EXPECT_LE(mean_distance[1], mean_distance[2]);
  EXPECT_LT(mean_distance[0], mean_distance[2]);
  EXPECT_GT(mean_distance[2], 0.0);
  // Still closer to the original than an unrelated descriptor (128 of 256 bits) would be.
  EXPECT_LT(mean_distance[2], 128.0);
}

// --- Regression reference --------------------------------------------------------------------

// The reference patch: a ramp, an 8 x 8 checkerboard and a modular texture, integers only.
int ReferencePatchValue(int y, int x) {
  return (3 * x + 2 * y + 3 * ((x * y) % 37) + 40 * ((x / 8 + y / 8) % 2)) % 256;
}

std::string Hex(const cv::Mat& row) {
  static const char kDigits[] = "0123456789abcdef";
  std::string out;
  for (int i = 0; i < row.cols; ++i) {
    const unsigned v = row.at<std::uint8_t>(0, i);
    out += kDigits[v >> 4];
    out += kDigits[v & 15u];
  }
  return out;
}

struct ReferenceCase {
  const char* key;
  int bits;
  LdbSelection selection;
};
const ReferenceCase kReferenceCases[] = {
    {"full_1386", 1386, LdbSelection::kRandom},
    {"random_256", 256, LdbSelection::kRandom},
    {"coarse_first_256", 256, LdbSelection::kCoarseFirst},
};

TEST(LdbTest, MatchesReferenceFile) {
  const std::string path = testing::SourceDir() + "/tests/data/ldb_reference.txt";
  const cv::Mat patch = FromFunction(64, ReferencePatchValue);

  if (std::getenv("OPENABLE_WRITE_LDB_REFERENCE") != nullptr) {
    std::ofstream out(path);
    out << "# LDB regression reference, checked by LdbTest.MatchesReferenceFile\n"
           "# (tests/descriptors/ldb_test.cc). Patch: 64 x 64, value at row y, column x =\n"
           "# (3x + 2y + 3((x y) mod 37) + 40((x/8 + y/8) mod 2)) mod 256, integer division.\n"
           "# Each line: key, then the descriptor bytes in hex (byte 0 first; bit k of the\n"
           "# descriptor is bit k % 8 of byte k / 8). Regenerate only after an intended change:\n"
           "# OPENABLE_WRITE_LDB_REFERENCE=1 descriptors_tests "
           "--gtest_filter=LdbTest.MatchesReferenceFile\n";
    for (const ReferenceCase& c : kReferenceCases) {
      out << c.key << " " << Hex(Describe(LdbDescriptor(Options(64, c.bits), c.selection), patch))
          << "\n";
    }
    ASSERT_TRUE(out.good()) << path;
  }

  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << "missing " << path;
  std::string line;
  int checked = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string key, hex;
    fields >> key >> hex;
    bool known = false;
    for (const ReferenceCase& c : kReferenceCases) {
      if (key != c.key) continue;
      known = true;
      const LdbDescriptor d(Options(64, c.bits), c.selection);
      EXPECT_EQ(Hex(Describe(d, patch)), hex) << key;
      ++checked;
    }
    EXPECT_TRUE(known) << "unknown key " << key;
  }
  EXPECT_EQ(checked, 3);
}

}  // namespace
}  // namespace openable
