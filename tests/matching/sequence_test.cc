#include "matching/sequence.h"

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

// Naive definition: sum over k of the terms that exist, scaled to L terms.
cv::Mat1f NaiveSequence(const cv::Mat1f& d, int L, const std::vector<int>& rs,
                        const std::vector<int>& cs) {
  cv::Mat1f out(d.size());
  for (int i = 0; i < d.rows; ++i)
    for (int j = 0; j < d.cols; ++j) {
      double sum = 0;
      int count = 0;
      for (int k = 0; k < L; ++k) {
        if (i - k < StartOf(rs, i) || j - k < StartOf(cs, j)) break;
        sum += d(i - k, j - k);
        ++count;
      }
      out(i, j) = static_cast<float>(sum * L / count);
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

TEST(SequenceDistances, RejectsBadArguments) {
  const cv::Mat1f d = Random(4, 4, 5);
  EXPECT_THROW(SequenceDistances(d, 0), std::logic_error);
  EXPECT_THROW(SequenceDistances(d, 2, {1}, {0}), std::logic_error);
  EXPECT_THROW(SequenceDistances(d, 2, {0, 3, 2}, {0}), std::logic_error);
}

}  // namespace
}  // namespace openable
