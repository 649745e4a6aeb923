#include "matching/distances.h"

#include <gtest/gtest.h>

#include <bitset>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "tests/matching/random_rows.h"

namespace openable {
namespace {

using matching_test::RandomBytes;

// Brute force: count the differing bits one bit at a time.
int BitCount(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  int bits = 0;
  for (int k = 0; k < a.cols; ++k)
    for (int bit = 0; bit < 8; ++bit)
      bits += ((a.at<std::uint8_t>(i, k) >> bit) & 1) != ((b.at<std::uint8_t>(j, k) >> bit) & 1);
  return bits;
}

TEST(HammingDistance, CountsBitsNotBytes) {
  // 0x01 vs 0x80 differ in 2 bits; the original's "sum of XOR-ed bytes" would say 129.
  const std::uint8_t a[1] = {0x01}, b[1] = {0x80};
  EXPECT_EQ(HammingDistance(a, b, 1), 2);
  const std::uint8_t c[9] = {0xFF, 0, 0, 0, 0, 0, 0, 0, 0x0F}, z[9] = {};
  EXPECT_EQ(HammingDistance(c, z, 9), 12);
}

class HammingWidths : public ::testing::TestWithParam<int> {};

TEST_P(HammingWidths, MatrixMatchesBruteForce) {
  const int width = GetParam();
  const cv::Mat a = RandomBytes(37, width, 1 + width), b = RandomBytes(23, width, 99 + width);
  for (HammingKernel kernel :
       {HammingKernel::kPortable, HammingKernel::kPopcnt, HammingKernel::kAvx2,
        HammingKernel::kAvx512, HammingKernel::kAuto}) {
    if (!ForceHammingKernel(kernel)) {  // the CPU lacks it: said, not hidden
      std::printf("[ SKIPPED  ] Hamming kernel %d: this CPU lacks it\n", static_cast<int>(kernel));
      continue;
    }
    SCOPED_TRACE(HammingKernelName());
    for (int threads : {1, 2, 3}) {
      const cv::Mat1f cross = HammingDistances(a, b, threads);
      ASSERT_EQ(cross.rows, 37);
      ASSERT_EQ(cross.cols, 23);
      for (int i = 0; i < a.rows; ++i)
        for (int j = 0; j < b.rows; ++j)
          ASSERT_EQ(cross(i, j), BitCount(a, i, b, j)) << i << "," << j;
      const cv::Mat1f self = HammingDistances(a, cv::Mat(), threads);
      for (int i = 0; i < a.rows; ++i)
        for (int j = 0; j < a.rows; ++j)
          ASSERT_EQ(self(i, j), BitCount(a, i, a, j)) << i << "," << j;
      for (int i = 0; i < a.rows; ++i)
        EXPECT_EQ(HammingDistance(a.ptr<std::uint8_t>(i), b.ptr<std::uint8_t>(0), width),
                  BitCount(a, i, b, 0));
    }
  }
  ForceHammingKernel(HammingKernel::kAuto);
}

// 256 and 300 bytes: more than 31 words, where the AVX2 kernel's byte counters are flushed.
INSTANTIATE_TEST_SUITE_P(Widths, HammingWidths,
                         ::testing::Values(1, 7, 8, 9, 32, 64, 174, 256, 300));

TEST(HammingKernel, TheBestKernelOfTheCpuIsChosen) {
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                      __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512vpopcntdq");
  const std::string expected = avx512                             ? "avx512"
                               : __builtin_cpu_supports("avx2")   ? "avx2"
                               : __builtin_cpu_supports("popcnt") ? "popcnt"
                                                                  : "portable";
  EXPECT_EQ(HammingKernelName(), expected);
}

TEST(HammingDistances, ReportsProgressUpToTheTotal) {
  const cv::Mat a = RandomBytes(50, 32, 5);
  std::int64_t last = -1, total_seen = 0;
  HammingDistances(a, cv::Mat(), 2, [&](std::int64_t done, std::int64_t total) {
    EXPECT_GE(done, last);
    last = done;
    total_seen = total;
  });
  EXPECT_EQ(total_seen, 50 * 50);  // every cell is computed
  EXPECT_EQ(last, total_seen);
}

TEST(HammingDistances, RejectsMismatchedWidths) {
  EXPECT_THROW(HammingDistances(RandomBytes(2, 8, 1), RandomBytes(2, 9, 1)), std::logic_error);
  EXPECT_THROW(HammingDistances(cv::Mat1f(2, 8, 0.f)), std::logic_error);
}

double DirectL2(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  double s = 0;
  for (int k = 0; k < a.cols; ++k) {
    const double d = static_cast<double>(a.at<float>(i, k)) - b.at<float>(j, k);
    s += d * d;
  }
  return std::sqrt(s);
}

TEST(L2Distances, MatchesDirectSumIncludingNearDuplicates) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.f, 1.f);
  const int d = 300;
  cv::Mat1f a(40, d), b(30, d);
  for (auto& v : a) v = 5.f + g(rng);  // large common offset: cancellation-prone
  for (int j = 0; j < b.rows; ++j)
    for (int k = 0; k < d; ++k)
      b(j, k) = j < 10 ? a(j, k) + 1e-3f * g(rng) : 5.f + g(rng);  // 10 near-duplicates
  for (int threads : {1, 2}) {
    const cv::Mat1f cross = L2Distances(a, b, threads);
    for (int i = 0; i < a.rows; ++i)
      for (int j = 0; j < b.rows; ++j) {
        const double expected = DirectL2(a, i, b, j);
        ASSERT_NEAR(cross(i, j), expected, 1e-4 * (1.0 + expected)) << i << "," << j;
      }
    const cv::Mat1f self = L2Distances(a, cv::Mat(), threads);
    for (int i = 0; i < a.rows; ++i) {
      EXPECT_EQ(self(i, i), 0.f);
      for (int j = 0; j < a.rows; ++j) {
        EXPECT_EQ(self(i, j), self(j, i));
        ASSERT_NEAR(self(i, j), DirectL2(a, i, a, j), 1e-4 * (1.0 + DirectL2(a, i, a, j)));
      }
    }
  }
}

TEST(L2Distances, HandWorkedValues) {
  cv::Mat1f a = (cv::Mat1f(2, 2) << 0, 0, 3, 4);
  cv::Mat1f b = (cv::Mat1f(1, 2) << 6, 8);
  const cv::Mat1f cross = L2Distances(a, b);
  EXPECT_FLOAT_EQ(cross(0, 0), 10.f);
  EXPECT_FLOAT_EQ(cross(1, 0), 5.f);
}

// --- L1 (SAD rows) ---------------------------------------------------------------------------

// Widths around the 32-byte step of the AVX2 kernel, and one that overflows 16-bit sums.
TEST(L1Distances, MatchesDirectSumOfAbsoluteDifferences) {
  std::mt19937 rng(12);
  std::uniform_int_distribution<int> byte(0, 255);
  for (const int w : {1, 31, 32, 33, 64, 100, 2048}) {
    cv::Mat a(9, w, CV_8U), b(7, w, CV_8U);
    for (int i = 0; i < a.rows; ++i)
      for (int k = 0; k < w; ++k) a.at<std::uint8_t>(i, k) = static_cast<std::uint8_t>(byte(rng));
    for (int i = 0; i < b.rows; ++i)
      for (int k = 0; k < w; ++k) b.at<std::uint8_t>(i, k) = static_cast<std::uint8_t>(byte(rng));
    a.row(0).setTo(0);
    b.row(0).setTo(255);  // the largest difference of every byte
    for (int threads : {1, 2}) {
      const cv::Mat1f cross = L1Distances(a, b, threads);
      ASSERT_EQ(cross.size(), cv::Size(b.rows, a.rows));
      for (int i = 0; i < a.rows; ++i)
        for (int j = 0; j < b.rows; ++j) {
          long long direct = 0;
          for (int k = 0; k < w; ++k)
            direct += std::abs(int(a.at<std::uint8_t>(i, k)) - int(b.at<std::uint8_t>(j, k)));
          ASSERT_EQ(cross(i, j), static_cast<float>(direct)) << "w=" << w << " " << i << "," << j;
          ASSERT_EQ(RowDistance(a, i, b, j, Metric::kL1), static_cast<float>(direct));
        }
      EXPECT_EQ(cross(0, 0), 255.f * w);
      const cv::Mat1f self = L1Distances(a, cv::Mat(), threads);
      for (int i = 0; i < a.rows; ++i) {
        EXPECT_EQ(self(i, i), 0.f);
        for (int j = 0; j < a.rows; ++j) EXPECT_EQ(self(i, j), self(j, i));
      }
    }
  }
}

TEST(L1Distances, DistancesPicksTheMetricAndRefusesFloatRows) {
  const cv::Mat a = (cv::Mat_<std::uint8_t>(2, 2) << 0, 10, 3, 1);
  // L1: |0-3| + |10-1| = 12; Hamming: popcount(0^3) + popcount(10^1) = 2 + 3 = 5.
  EXPECT_EQ(Distances(a, cv::Mat(), Metric::kL1)(0, 1), 12.f);
  EXPECT_EQ(Distances(a, cv::Mat(), Metric::kHamming)(0, 1), 5.f);
  EXPECT_EQ(MetricOfType(CV_8U), Metric::kHamming);
  EXPECT_EQ(MetricOfType(CV_32F), Metric::kL2);
  EXPECT_THROW(L1Distances(cv::Mat1f(2, 2, 0.f)), std::logic_error);
}

}  // namespace
}  // namespace openable
