#include "OpenABLE/evaluation/unsupervised.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

namespace openable {
namespace {

// Queries x references distances of two traversals of one route: query q is reference q +
// offset, distances growing with the distance along the route, plus noise.
cv::Mat1f Route(int queries, int references, int offset, unsigned seed, float noise = 0.3f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, noise);
  cv::Mat1f m(queries, references);
  for (int q = 0; q < queries; ++q)
    for (int j = 0; j < references; ++j)
      m(q, j) = std::min(1.f, std::abs(j - q - offset) / 20.f) + u(rng);
  return m;
}

// Brute force of the definitions of unsupervised.h: best = smallest finite cell (lowest
// column on ties), ratio to the smallest finite cell more than `window` away (1 without one or
// when it is 0), the partner by exhaustive search over disjoint windows (scale: q - L + 1 .. q),
// agreement within the tolerance.
struct Brute {
  double distinctiveness = 0, consistency = 0;
};
Brute BruteForce(const cv::Mat1f& m, int L, int window) {
  const int nq = m.rows, nr = m.cols;
  std::vector<int> best(nq, -1);
  double margin = 0;
  for (int q = 0; q < nq; ++q) {
    for (int j = 0; j < nr; ++j)
      if (std::isfinite(m(q, j)) && (best[q] < 0 || m(q, j) < m(q, best[q]))) best[q] = j;
    if (best[q] < 0) continue;
    float rival = std::numeric_limits<float>::infinity();
    for (int j = 0; j < nr; ++j)
      if (std::abs(j - best[q]) > window && std::isfinite(m(q, j)))
        rival = std::min(rival, m(q, j));
    const double ratio = std::isfinite(rival) && rival > 0 ? m(q, best[q]) / rival : 1.0;
    margin += 1.0 - ratio;
  }
  const int gap = std::max(L, 10), tolerance = std::max(3, (gap + 5) / 10);
  int agreeing = 0;
  for (int q = 0; q < nq; ++q) {
    if (best[q] < 0) continue;
    // Windows q - L + 1 .. q are disjoint when the queries are at least L apart.
    int p = q - gap >= 0 ? q - gap : (q + gap < nq ? q + gap : -1);
    if (p < 0 || best[p] < 0) continue;
    agreeing += std::abs((best[q] - best[p]) - (q - p)) <= tolerance;
  }
  return {margin / nq, static_cast<double>(agreeing) / nq};
}

UnsupervisedOptions Options(int L) {
  UnsupervisedOptions o;
  o.agreement.sequence_length = L;
  o.agreement.partial = SequencePartial::kScale;
  o.score.window = 10;
  return o;
}

TEST(Unsupervised, FiguresEqualTheBruteForceDefinitions) {
  for (int L : {1, 5, 12}) {
    for (unsigned seed : {1u, 2u}) {
      cv::Mat1f m = Route(90, 120, 7, seed, 0.8f);
      m(3, 5) = std::numeric_limits<float>::infinity();  // cells without a value
      for (int j = 0; j < 120; ++j) m(60, j) = std::numeric_limits<float>::infinity();
      const UnsupervisedFigures f =
          UnsupervisedCriteria(m, EvaluationLayout::QueryReference(90, 120), Options(L));
      const Brute b = BruteForce(m, L, 10);
      EXPECT_NEAR(f.distinctiveness, b.distinctiveness, 1e-9) << L;
      EXPECT_NEAR(f.consistency, b.consistency, 1e-12) << L;
      EXPECT_NEAR(f.agreement, (10 * b.consistency + b.distinctiveness) / 11, 1e-9);
      EXPECT_EQ(f.queries, 90);
      EXPECT_EQ(f.answered, 89);  // row 60 has no value
      EXPECT_EQ(f.best[60], -1);
      EXPECT_EQ(f.gap, std::max(L, 10));
    }
  }
}

// A clean diagonal ranks above the same rows shuffled (the route's order lost).
TEST(Unsupervised, CleanDiagonalRanksAboveShuffledRows) {
  const cv::Mat1f clean = Route(100, 100, 0, 3, 0.02f);
  std::vector<int> order(100);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(5));
  cv::Mat1f shuffled(100, 100);
  for (int q = 0; q < 100; ++q) clean.row(order[q]).copyTo(shuffled.row(q));
  const auto layout = EvaluationLayout::QueryReference(100, 100);
  const UnsupervisedFigures a = UnsupervisedCriteria(clean, layout, Options(1));
  const UnsupervisedFigures b = UnsupervisedCriteria(shuffled, layout, Options(1));
  EXPECT_DOUBLE_EQ(a.consistency, 1.0);
  EXPECT_NEAR(a.distinctiveness, b.distinctiveness, 1e-9);  // the same rows
  EXPECT_LT(b.consistency, 0.1);
  EXPECT_GT(a.agreement, b.agreement + 0.5);
}

// Best matches that all fall on one column rank low however distinct they are: distinctiveness
// alone would put them first.
TEST(Unsupervised, BestMatchesOnOneColumnRankLowHoweverDistinct) {
  cv::Mat1f attractor(100, 100, 1.0f);
  for (int q = 0; q < 100; ++q) attractor(q, 42) = 0.01f;  // distinct: ratio 0.01
  const cv::Mat1f route = Route(100, 100, 0, 4);
  const auto layout = EvaluationLayout::QueryReference(100, 100);
  const UnsupervisedFigures a = UnsupervisedCriteria(attractor, layout, Options(10));
  const UnsupervisedFigures r = UnsupervisedCriteria(route, layout, Options(10));
  EXPECT_NEAR(a.distinctiveness, 0.99, 1e-6);
  EXPECT_GT(a.distinctiveness, r.distinctiveness);
  EXPECT_DOUBLE_EQ(a.consistency, 0.0);
  EXPECT_LT(a.agreement, r.agreement);
}

// One sequence (loop closure): only queries with candidates count, and a revisit's answers
// agree along it.
TEST(Unsupervised, LoopClosureCountsTheQueriesWithCandidates) {
  const int n = 300;
  cv::Mat1f m(n, n, 1.0f);
  for (int q = 200; q < n; ++q) m(q, q - 150) = 0.1f;  // frames 200-299 revisit 50-149
  UnsupervisedOptions o = Options(1);
  o.exclusion = 100;
  const UnsupervisedFigures f = UnsupervisedCriteria(m, EvaluationLayout::LoopClosure(n), o);
  EXPECT_EQ(f.queries, n - 100);  // frames 100.. have a candidate (j <= q - 100)
  // The revisit's queries whose partner, 10 back, is in the revisit too (210-299); the others
  // answer column 0 every time (all alike), which never advances with the queries.
  EXPECT_EQ(f.agreeing, 90);
  EXPECT_NEAR(f.consistency, 90.0 / 200, 1e-12);
}

}  // namespace
}  // namespace openable
