#include "matching/sequence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "OpenABLE/base/threading.h"

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
  const cv::Mat1f s =
      SequenceDistances(d, 2, {}, {}, SequenceDirection::kForward, 0, SequencePartial::kScale);
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
    const cv::Mat1f fast =
        SequenceDistances(d, L, {}, {}, SequenceDirection::kForward, 0, SequencePartial::kScale);
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
    const cv::Mat1f fast = SequenceDistances(d, L, starts, starts, SequenceDirection::kForward, 0,
                                             SequencePartial::kScale);
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
      const SequencePartial scale = SequencePartial::kScale;
      SequenceDistancesInPlace(in_place, L, rows, cols, SequenceDirection::kReverse, threads,
                               scale);
      EXPECT_LE(cv::norm(in_place, rev, cv::NORM_INF), 1e-3) << "L=" << L << " t=" << threads;
      EXPECT_LE(
          cv::norm(SequenceDistances(d, L, rows, cols, SequenceDirection::kForward, threads, scale),
                   fwd, cv::NORM_INF),
          1e-3)
          << "L=" << L << " t=" << threads;
      EXPECT_LE(
          cv::norm(SequenceDistances(d, L, rows, cols, SequenceDirection::kBoth, threads, scale),
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

// Naive definition of Sequence_partial ahead, written from the rule and not from AheadShift:
// walk the cells of (i, j)'s diagonal that lie in the traversal of i and in that of j, in order;
// with fewer than L of them the cell is +inf; at position p >= L - 1 it sums cells p - L + 1 ..
// p, and before that the first L cells of the diagonal.
cv::Mat1f NaiveAhead(const cv::Mat1f& d, int L, const std::vector<int>& rs,
                     const std::vector<int>& cs, bool reverse = false) {
  cv::Mat1f out(d.size());
  for (int i = 0; i < d.rows; ++i)
    for (int j = 0; j < d.cols; ++j) {
      const int r0 = StartOf(rs, i), r1 = EndOf(rs, i, d.rows);
      const int c0 = StartOf(cs, j), c1 = EndOf(cs, j, d.cols);
      const int dj = reverse ? -1 : 1;  // the column's step as the row goes forward
      int a = i, b = j;                 // walk back to where the diagonal enters
      while (a - 1 >= r0 && b - dj >= c0 && b - dj < c1) --a, b -= dj;
      int cells = 0;  // the diagonal's cells inside both traversals
      for (int x = a, y = b; x < r1 && y >= c0 && y < c1; ++x, y += dj) ++cells;
      const int p = i - a;
      if (cells < L) {
        out(i, j) = std::numeric_limits<float>::infinity();
        continue;
      }
      const int first = p >= L - 1 ? p - L + 1 : 0;
      double sum = 0;
      for (int k = first; k < first + L; ++k) sum += d(a + k, b + k * dj);
      out(i, j) = static_cast<float>(sum);
    }
  return out;
}

// Sequence_partial ahead: every cell against the naive rule, along diagonals, anti-diagonals
// and both, with two traversals along rows and three along columns, on 1-3 threads; cells of
// diagonals shorter than L are +inf, and no finite cell sums fewer than L terms.
TEST(SequenceDistances, AheadMatchesTheNaiveRule) {
  const cv::Mat1f d = Random(45, 300, 12);
  const std::vector<int> rows = {0, 20}, cols = {0, 120, 250};
  const float inf = std::numeric_limits<float>::infinity();
  for (int L : {1, 2, 3, 10, 25, 60}) {
    const cv::Mat1f fwd = NaiveAhead(d, L, rows, cols);
    const cv::Mat1f rev = NaiveAhead(d, L, rows, cols, true);
    for (int threads : {1, 3}) {
      const auto got = [&](SequenceDirection dir) {
        return SequenceDistances(d, L, rows, cols, dir, threads, SequencePartial::kAhead);
      };
      const cv::Mat1f f = got(SequenceDirection::kForward), r = got(SequenceDirection::kReverse),
                      b = got(SequenceDirection::kBoth);
      // Cells whose emptiness differs from the naive rule's, and the largest difference of the
      // others (counted here, one assertion per matrix).
      int wrong_empty = 0;
      double largest = 0;
      const auto compare = [&](float got_value, float want) {
        if ((got_value == inf) != (want == inf)) {
          ++wrong_empty;
        } else if (want != inf) {
          largest = std::max(largest, static_cast<double>(std::abs(got_value - want)));
        }
      };
      for (int i = 0; i < d.rows; ++i)
        for (int j = 0; j < d.cols; ++j) {
          compare(f(i, j), fwd(i, j));
          compare(r(i, j), rev(i, j));
          compare(b(i, j), std::min(fwd(i, j), rev(i, j)));
        }
      EXPECT_EQ(wrong_empty, 0) << "L=" << L << " threads=" << threads;
      EXPECT_LE(largest, 1e-3) << "L=" << L << " threads=" << threads;
    }
  }
  // By hand, L = 3 on one 4 x 4 traversal: (0, 1) sums (0,1), (1,2), (2,3) = 2 + 7 + 12;
  // (1, 0) sums (1,0), (2,1), (3,2) = 5 + 10 + 15; (0, 2) has a diagonal of two cells: +inf;
  // (3, 3) sums its own three.
  const cv::Mat1f h = (cv::Mat1f(4, 4) << 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16);
  const cv::Mat1f s =
      SequenceDistances(h, 3, {}, {}, SequenceDirection::kForward, 1, SequencePartial::kAhead);
  EXPECT_FLOAT_EQ(s(0, 1), 21.f);
  EXPECT_FLOAT_EQ(s(1, 0), 30.f);
  EXPECT_EQ(s(0, 2), inf);
  EXPECT_FLOAT_EQ(s(3, 3), 16.f + 11.f + 6.f);
  EXPECT_FLOAT_EQ(s(0, 0), s(2, 2));
}

// FillAheadCells on a matrix swept with skip gives the ahead matrix (what a run over several
// processes does once it has gathered its rows).
TEST(SequenceDistances, FillAheadCellsCompletesASkipSweep) {
  const cv::Mat1f d = Random(45, 300, 13);
  const std::vector<int> rows = {0, 20}, cols = {0, 120, 250};
  for (const bool reverse : {false, true}) {
    const SequenceDirection dir =
        reverse ? SequenceDirection::kReverse : SequenceDirection::kForward;
    cv::Mat1f skip = SequenceDistances(d, 10, rows, cols, dir, 2, SequencePartial::kSkip);
    FillAheadCells(skip, 10, rows, cols, reverse);
    const cv::Mat1f ahead = SequenceDistances(d, 10, rows, cols, dir, 2, SequencePartial::kAhead);
    EXPECT_EQ(cv::norm(skip != ahead, cv::NORM_L1), 0.0) << reverse;
  }
}

// SequenceCellDistance with ahead gives the matrix's cell, for early cells too (queries and
// references as separate traversals).
TEST(SequenceDistances, CellDistanceAheadEqualsTheMatrix) {
  cv::RNG rng(14);
  cv::Mat queries(30, 8, CV_8U), references(25, 8, CV_8U);
  rng.fill(queries, cv::RNG::UNIFORM, 0, 256);
  rng.fill(references, cv::RNG::UNIFORM, 0, 256);
  cv::Mat1f single(30, 25);
  for (int q = 0; q < 30; ++q)
    for (int j = 0; j < 25; ++j)
      single(q, j) =
          static_cast<float>(cv::norm(queries.row(q), references.row(j), cv::NORM_HAMMING));
  for (const bool reverse : {false, true}) {
    const cv::Mat1f s = SequenceDistances(
        single, 7, {}, {}, reverse ? SequenceDirection::kReverse : SequenceDirection::kForward, 1,
        SequencePartial::kAhead);
    for (int q = 0; q < 30; ++q)
      for (int j = 0; j < 25; ++j)
        ASSERT_EQ(SequenceCellDistance(queries, q, references, j, 7, reverse, nullptr,
                                       SequencePartial::kAhead),
                  s(q, j))
            << reverse << " " << q << "," << j;
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

namespace openable {
namespace {

std::atomic<int> g_sequence_checks{0};
void StopOnFirstCheck() {
  ++g_sequence_checks;
  throw std::runtime_error("stopped");
}

// The sums of a large matrix take seconds: the host's interrupt check (Ctrl-C in Python) runs
// between rows, and its exception ends the sweep on every thread at the same row, well before
// the end, and reaches the caller.
TEST(SequenceDistances, AnInterruptCheckStopsTheSumsWithinTheirRows) {
  cv::Mat1f d(8000, 8000);  // about 0.2 s of sums on 2 cores, against 50 ms between checks
  cv::randu(d, 0.0f, 1.0f);
  const cv::Mat1f before = d.clone();
  for (const SequenceDirection direction :
       {SequenceDirection::kForward, SequenceDirection::kBoth}) {
    cv::Mat1f work = before.clone();
    SetInterruptCheck(&StopOnFirstCheck);
    g_sequence_checks = 0;
    EXPECT_THROW(SequenceDistancesInPlace(work, 10, {0}, {0}, direction, 2), std::runtime_error);
    SetInterruptCheck(nullptr);
    EXPECT_EQ(g_sequence_checks.load(), 1);
    // Stopped part-way: the last rows still hold the single-frame distances.
    EXPECT_EQ(cv::norm(work.rowRange(7990, 8000), before.rowRange(7990, 8000), cv::NORM_INF), 0.0);
  }
  // With no check installed the sums run to the end.
  cv::Mat1f whole = before.clone();
  SequenceDistancesInPlace(whole, 10, {0}, {0}, SequenceDirection::kForward, 2);
  EXPECT_GT(cv::norm(whole.rowRange(7990, 8000), before.rowRange(7990, 8000), cv::NORM_INF), 0.0);
}

// Row by row, with the query rows one traversal and the columns in sessions: the cells of the
// naive definition (scaled or skipped), exactly for integer distances.
TEST(SequenceRowSums, EqualTheNaiveDefinitionRowByRow) {
  for (const int L : {1, 2, 5, 13}) {
    for (const SequencePartial partial : {SequencePartial::kScale, SequencePartial::kSkip}) {
      cv::Mat1f d = Random(40, 33, 7 + L);
      for (auto& v : d) v = std::round(v);  // integers: the double sums are exact
      const std::vector<int> cols = {0, 9, 20};
      const cv::Mat1f want =
          NaiveSequence(d, L, {}, cols, false, partial == SequencePartial::kSkip);
      SequenceRowSums rows(L, partial);
      for (int i = 0; i < d.rows; ++i) {
        std::vector<float> row(d.ptr<float>(i), d.ptr<float>(i) + d.cols);
        rows.Push(row.data(), d.cols, cols);
        for (int j = 0; j < d.cols; ++j)
          EXPECT_EQ(row[static_cast<size_t>(j)], want(i, j))
              << "L " << L << " cell " << i << ", " << j;
      }
      EXPECT_EQ(rows.Rows(), d.rows);
      // Restart: the next row is the first of another traversal, as a matrix of its own.
      rows.Restart();
      std::vector<float> first(d.ptr<float>(5), d.ptr<float>(5) + d.cols);
      rows.Push(first.data(), d.cols, cols);
      const cv::Mat1f alone = NaiveSequence(d.rowRange(5, 6).clone(), L, {}, cols, false,
                                            partial == SequencePartial::kSkip);
      for (int j = 0; j < d.cols; ++j) EXPECT_EQ(first[static_cast<size_t>(j)], alone(0, j));
    }
  }
}

// The same floats as the sweep over the whole matrix (the same running operations in double),
// for real-valued distances too.
TEST(SequenceRowSums, GiveTheSweepsFloats) {
  const cv::Mat1f d = Random(60, 50, 3);
  const std::vector<int> cols = {0, 25};
  const cv::Mat1f sweep =
      SequenceDistances(d, 7, {}, cols, SequenceDirection::kForward, 2, SequencePartial::kScale);
  SequenceRowSums rows(7);
  for (int i = 0; i < d.rows; ++i) {
    std::vector<float> row(d.ptr<float>(i), d.ptr<float>(i) + d.cols);
    rows.Push(row.data(), d.cols, cols);
    for (int j = 0; j < d.cols; ++j) EXPECT_EQ(row[static_cast<size_t>(j)], sweep(i, j));
  }
}

// Columns that become candidates one per row (the online detector: a frame of its own
// traversal exclusion frames back), and a session start that appears among them: each row's
// cells are those of the naive definition over the columns it has.
TEST(SequenceRowSums, ColumnsThatGrowByOneARow) {
  cv::Mat1f d = Random(50, 50, 11);
  for (auto& v : d) v = std::round(v);
  const int L = 6, first_own = 20;
  SequenceRowSums rows(L);
  const cv::Mat1f want = NaiveSequence(d, L, {}, {0, first_own});
  int columns = 20;
  for (int i = 0; i < 30; ++i) {
    if (i >= 10) ++columns;  // from row 10 on, one more column a row
    const std::vector<int> starts =
        columns > first_own ? std::vector<int>{0, first_own} : std::vector<int>{0};
    std::vector<float> row(d.ptr<float>(i), d.ptr<float>(i) + columns);
    rows.Push(row.data(), columns, starts);
    for (int j = 0; j < columns; ++j)
      EXPECT_EQ(row[static_cast<size_t>(j)], want(i, j)) << "cell " << i << ", " << j;
  }
}

TEST(SequenceRowSums, RefuseWhatTheirSumsCannotFollow) {
  EXPECT_THROW(SequenceRowSums(0), std::logic_error);
  EXPECT_THROW(SequenceRowSums(3, SequencePartial::kAhead), std::logic_error);
  SequenceRowSums rows(3);
  std::vector<float> row(10, 1.0f);
  rows.Push(row.data(), 5, {0});
  EXPECT_THROW(rows.Push(row.data(), 7, {0}), std::logic_error);     // two columns more
  EXPECT_THROW(rows.Push(row.data(), 4, {0}), std::logic_error);     // one fewer
  EXPECT_THROW(rows.Push(row.data(), 6, {0, 2}), std::logic_error);  // a start among old columns
  rows.Push(row.data(), 6, {0, 5});                                  // a start at the new one
  rows.Restart();
  rows.Push(row.data(), 9, {0, 3});
  EXPECT_EQ(rows.Rows(), 1);
}

}  // namespace
}  // namespace openable
