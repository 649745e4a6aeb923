#include "matching/sequence.h"

#include <algorithm>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace openable {
namespace {

int StartOf(const std::vector<int>& starts, int x) {
  int s = 0;
  for (int v : starts)
    if (v <= x) s = v;
  return s;
}

int EndOf(const std::vector<int>& starts, int x, int n) {
  for (int v : starts)
    if (v > x) return v;  // first start after x: one past the last frame of x's traversal
  return n;
}

// Naive definition: sum over k of the terms that exist, scaled to L terms. reverse: the
// column runs forward (j + k) while the row runs back (i - k).
cv::Mat1f NaiveSequence(const cv::Mat1f& d, int L, const std::vector<int>& rs,
                        const std::vector<int>& cs, bool reverse = false, bool skip = false) {
  cv::Mat1f out(d.size());
  for (int i = 0; i < d.rows; ++i)
    for (int j = 0; j < d.cols; ++j) {
      double sum = 0;
      int count = 0;
      for (int k = 0; k < L; ++k) {
        const int jk = reverse ? j + k : j - k;
        if (i - k < StartOf(rs, i) || jk < StartOf(cs, j) || jk >= EndOf(cs, j, d.cols)) break;
        sum += d(i - k, jk);
        ++count;
      }
      out(i, j) = skip && count < L ? std::numeric_limits<float>::infinity()
                                    : static_cast<float>(sum * L / count);
    }
  return out;
}

cv::Mat1f Random(int n, int m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 100.f);
  cv::Mat1f d(n, m);
  for (auto& v : d) v = u(rng);
  return d;
}

TEST(SequenceDistances, LengthOneIsTheInput) {
  const cv::Mat1f d = Random(9, 7, 1);
  EXPECT_EQ(cv::norm(SequenceDistances(d, 1), d, cv::NORM_INF), 0.0);
}

TEST(SequenceDistances, HandWorkedThreeByThree) {
  cv::Mat1f d = (cv::Mat1f(3, 3) << 1, 2, 3, 4, 5, 6, 7, 8, 9);
  const cv::Mat1f s = SequenceDistances(d, 2);
  // (2,2): d(2,2) + d(1,1) = 9 + 5; (1,2): 6 + 2; (2,1): 8 + 4;
  // (0,0): one term, 1 scaled by 2/1; (2,0): 7 * 2.
  EXPECT_FLOAT_EQ(s(2, 2), 14.f);
  EXPECT_FLOAT_EQ(s(1, 2), 8.f);
  EXPECT_FLOAT_EQ(s(2, 1), 12.f);
  EXPECT_FLOAT_EQ(s(0, 0), 2.f);
  EXPECT_FLOAT_EQ(s(2, 0), 14.f);
}

TEST(SequenceDistances, MatchesNaiveLoopForSeveralLengths) {
  const cv::Mat1f d = Random(41, 33, 3);
  for (int L : {1, 2, 3, 5, 10, 40, 60}) {
    const cv::Mat1f fast = SequenceDistances(d, L);
    const cv::Mat1f slow = NaiveSequence(d, L, {0}, {0});
    for (int i = 0; i < d.rows; ++i)
      for (int j = 0; j < d.cols; ++j)
        ASSERT_NEAR(fast(i, j), slow(i, j), 1e-3) << "L=" << L << " at " << i << "," << j;
  }
}

TEST(SequenceDistances, SumsNeverCrossTraversals) {
  // Two traversals concatenated: frames 0-19 and 20-44.
  const cv::Mat1f d = Random(45, 45, 4);
  const std::vector<int> starts = {0, 20};
  for (int L : {1, 4, 10, 25}) {
    const cv::Mat1f fast = SequenceDistances(d, L, starts, starts);
    const cv::Mat1f slow = NaiveSequence(d, L, starts, starts);
    for (int i = 0; i < d.rows; ++i)
      for (int j = 0; j < d.cols; ++j)
        ASSERT_NEAR(fast(i, j), slow(i, j), 1e-3) << "L=" << L << " at " << i << "," << j;
  }
}

// Anti-diagonals (reference route driven the other way), with traversals, on 1-3 threads,
// in place; and kBoth as the element-wise minimum of the two naive sums.
TEST(SequenceDistances, ReverseAndBothMatchNaiveLoops) {
  const cv::Mat1f d = Random(45, 300, 6);  // wide enough for several column chunks
  const std::vector<int> rows = {0, 20}, cols = {0, 120, 250};
  for (int L : {1, 3, 10, 25, 400}) {
    const cv::Mat1f fwd = NaiveSequence(d, L, rows, cols);
    const cv::Mat1f rev = NaiveSequence(d, L, rows, cols, true);
    cv::Mat1f both(d.size());
    for (int i = 0; i < d.rows; ++i)
      for (int j = 0; j < d.cols; ++j) both(i, j) = std::min(fwd(i, j), rev(i, j));
    for (int threads : {1, 2, 3}) {
      cv::Mat1f in_place = d.clone();
      SequenceDistancesInPlace(in_place, L, rows, cols, SequenceDirection::kReverse, threads);
      EXPECT_LE(cv::norm(in_place, rev, cv::NORM_INF), 1e-3) << "L=" << L << " t=" << threads;
      EXPECT_LE(cv::norm(SequenceDistances(d, L, rows, cols, SequenceDirection::kForward, threads),
                         fwd, cv::NORM_INF),
                1e-3)
          << "L=" << L << " t=" << threads;
      EXPECT_LE(cv::norm(SequenceDistances(d, L, rows, cols, SequenceDirection::kBoth, threads),
                         both, cv::NORM_INF),
                1e-3)
          << "L=" << L << " t=" << threads;
    }
  }
}

// Sequence_partial skip: a cell with fewer than L terms holds +inf, and only those; along
// diagonals, anti-diagonals (which run off the end of the reference traversal) and both, with
// two traversals along rows and three along columns, on 1-3 threads.
TEST(SequenceDistances, SkipLeavesExactlyTheIncompleteCellsEmpty) {
  const cv::Mat1f d = Random(45, 300, 11);
  const std::vector<int> rows = {0, 20}, cols = {0, 120, 250};
  const float inf = std::numeric_limits<float>::infinity();
  for (int L : {1, 3, 10, 25, 400}) {
    const cv::Mat1f fwd = NaiveSequence(d, L, rows, cols, false, true);
    const cv::Mat1f rev = NaiveSequence(d, L, rows, cols, true, true);
    for (int threads : {1, 2, 3}) {
      const auto got = [&](SequenceDirection dir) {
        return SequenceDistances(d, L, rows, cols, dir, threads, SequencePartial::kSkip);
      };
      const cv::Mat1f f = got(SequenceDirection::kForward), r = got(SequenceDirection::kReverse),
                      b = got(SequenceDirection::kBoth);
      for (int i = 0; i < d.rows; ++i)
        for (int j = 0; j < d.cols; ++j) {
          ASSERT_EQ(f(i, j) == inf, fwd(i, j) == inf) << "L=" << L << " at " << i << "," << j;
          ASSERT_EQ(r(i, j) == inf, rev(i, j) == inf) << "L=" << L << " at " << i << "," << j;
          const float both = std::min(fwd(i, j), rev(i, j));
          ASSERT_EQ(b(i, j) == inf, both == inf) << "L=" << L << " at " << i << "," << j;
          if (fwd(i, j) != inf) {
            ASSERT_NEAR(f(i, j), fwd(i, j), 1e-3);
          }
          if (rev(i, j) != inf) {
            ASSERT_NEAR(r(i, j), rev(i, j), 1e-3);
          }
          if (both != inf) {
            ASSERT_NEAR(b(i, j), both, 1e-3);
          }
        }
      // Hand check: the first L - 1 rows of each row traversal are empty along diagonals.
      if (L > 1 && L <= 20) {
        EXPECT_EQ(f(L - 2, 200), inf);
        EXPECT_EQ(f(20 + L - 2, 200), inf);
        EXPECT_NE(f(L - 1, 200), inf);
        EXPECT_EQ(r(L - 1, 119), inf);  // the anti-diagonal runs off reference 0-119
        EXPECT_NE(r(L - 1, 120 - L), inf);
      }
    }
  }
}

// A long diagonal of a Hamming-like matrix (integers): the running sum in double stays exact.
TEST(SequenceDistances, LongDiagonalsStayExactForIntegerDistances) {
  cv::Mat1f d(2000, 2000);
  cv::RNG rng(8);
  for (auto& v : d) v = static_cast<float>(rng.uniform(0, 1387));
  const cv::Mat1f s = SequenceDistances(d, 30);
  for (int i : {29, 500, 1999}) {
    const int j = i;
    double sum = 0;
    for (int k = 0; k < 30; ++k) sum += d(i - k, j - k);
    EXPECT_EQ(s(i, j), static_cast<float>(sum)) << i;
  }
}

TEST(SequenceDistances, RejectsBadArguments) {
  const cv::Mat1f d = Random(4, 4, 5);
  EXPECT_THROW(SequenceDistances(d, 0), std::logic_error);
  EXPECT_THROW(SequenceDistances(d, 2, {1}, {0}), std::logic_error);
  EXPECT_THROW(SequenceDistances(d, 2, {0, 3, 2}, {0}), std::logic_error);
}

}  // namespace
}  // namespace openable
