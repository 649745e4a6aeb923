#include "matching/bounded.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>

#include "matching/distances.h"
#include "matching/normalize.h"
#include "matching/sequence.h"

namespace openable {
namespace {

cv::Mat RandomBinary(int rows, int cols, unsigned seed) {
  cv::Mat m(rows, cols, CV_8U);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

// Brute force: every cell with a value, sorted by (distance, reference), the first k kept.
std::vector<Match> SortedRow(const cv::Mat1f& s, int row, int q, int first, int count,
                             const KeepRules& rules) {
  std::vector<std::pair<float, int>> all;
  for (int j = 0; j < count; ++j)
    if ((!rules.one_traversal || j <= q - rules.exclusion) && std::isfinite(s(row, first + j)))
      all.emplace_back(s(row, first + j), j);
  std::sort(all.begin(), all.end());
  std::vector<Match> out;
  for (int r = 0; r < std::min<int>(rules.best, static_cast<int>(all.size())); ++r)
    out.push_back({q, all[r].second, all[r].first, r + 1});
  for (int j = std::max(0, q - rules.band);
       rules.band >= 0 && j <= std::min(count - 1, q + rules.band); ++j)
    if (std::isfinite(s(row, first + j)) &&
        std::none_of(out.begin(), out.end(),
                     [&](const Match& m) { return m.rank > 0 && m.reference == j; }))
      out.push_back({q, j, s(row, first + j), 0});
  return out;
}

void ExpectSame(const std::vector<Match>& a, const std::vector<Match>& b, float scale_b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].query, b[k].query) << k;
    EXPECT_EQ(a[k].reference, b[k].reference) << k;
    EXPECT_EQ(a[k].rank, b[k].rank) << k;
    EXPECT_NEAR(a[k].distance, b[k].distance * scale_b, 1e-5) << k;
  }
}

// The fused run against the dense matrix computed by the separate, tested pieces, then
// selected by brute force: one traversal (exclusion) and two (cross block), several L, every
// direction, Sequence_partial scale and ahead, with ranges of a few rows so that many range
// starts (and ends, which ahead reads past) are crossed.
TEST(BoundedMatches, EqualsBruteForceSelectionOfTheDenseMatrix) {
  const cv::Mat d = RandomBinary(150, 32, 3);
  for (const SequencePartial partial : {SequencePartial::kScale, SequencePartial::kAhead})
    for (int traversals : {1, 2}) {
      const std::vector<int> starts =
          traversals == 1 ? std::vector<int>{0} : std::vector<int>{0, 70};
      const MatchBlock block = BlockOf(starts, d.rows);
      KeepRules rules;
      rules.best = 4;
      rules.band = 2;
      rules.exclusion = 10;
      rules.one_traversal = block.one_traversal;
      for (int L : {1, 3, 8}) {
        for (auto dir :
             {SequenceDirection::kForward, SequenceDirection::kReverse, SequenceDirection::kBoth}) {
          SCOPED_TRACE("traversals " + std::to_string(traversals) + " L " + std::to_string(L) +
                       " direction " + std::to_string(static_cast<int>(dir)) + " partial " +
                       EnumName(partial));
          // Dense: the block of the full matrix, with sums restricted to the block's traversals.
          cv::Mat1f full = HammingDistances(d);
          SequenceDistancesInPlace(full, L, starts, starts, dir, 0, partial);
          std::vector<Match> expected;
          float block_max = 0;
          for (int q = 0; q < block.query_count; ++q) {
            const int row = block.query_first + q;
            for (int j = 0; j < block.reference_count; ++j)
              if (std::isfinite(full(row, block.reference_first + j)))
                block_max = std::max(block_max, full(row, block.reference_first + j));
            for (const Match& m :
                 SortedRow(full, row, q, block.reference_first, block.reference_count, rules))
              expected.push_back(m);
          }
          // Whole rows, and (along diagonals) tiles of 2 L or 12 columns rounded to blocks of
          // four: many tile edges, with sums and ahead cells reaching across them.
          for (const int tile : {-1, 9}) {
            SCOPED_TRACE("tile " + std::to_string(tile));
            BoundedOptions options;
            options.sequence_length = L;
            options.direction = dir;
            options.partial = partial;
            options.range_rows = 7;  // many ranges, each starting L - 1 rows early
            options.tile_columns = tile;
            float max_distance = 0;
            const std::vector<Match> got = BoundedMatches(d, block, rules, options, max_distance);
            EXPECT_FLOAT_EQ(max_distance, block_max);
            ExpectSame(got, expected, 1.0f / block_max);
          }
        }
      }
    }
}

// The hand-worked example of Match_consistency (tests/evaluation/metrics_test.cc) on the
// matches of rank 1: 30 queries answering reference q + 100 at score 0.5, but query 15 (900,
// 0.2) and query 25 (125, 0.95); threshold 0.9, L = 1, scale: the score alone accepts all but
// 25; one partner (10 queries apart) also refuses 15 and 5 (whose partner is 15).
TEST(AcceptedMatches, ConsistencyByHand) {
  std::vector<Match> matches;
  for (int q = 0; q < 30; ++q) {
    matches.push_back({q, q == 15 ? 900 : q + 100, 0.5f, 1, q == 15 ? 0.2f : 0.5f});
    matches.push_back({q, 400 + q, 0.7f, 2, 0.7f});  // rank 2: never an answer
  }
  matches[50].score = 0.95f;  // query 25's rank-1 match
  const std::vector<std::uint8_t> alone = AcceptedMatches(matches, 30, 0.9);
  EXPECT_EQ(std::count(alone.begin(), alone.end(), 1), 29);
  EXPECT_EQ(alone[25], 0);
  AgreementOptions a;
  a.sequence_length = 1;
  a.partial = SequencePartial::kScale;
  const std::vector<std::uint8_t> confirmed = AcceptedMatches(matches, 30, 0.9, &a);
  EXPECT_EQ(std::count(confirmed.begin(), confirmed.end(), 1), 27);
  for (int q : {5, 15, 25}) EXPECT_EQ(confirmed[q], 0) << q;
}

TEST(MatchesFromMatrix, SameSelectionAsBoundedOnOneTraversal) {
  const cv::Mat d = RandomBinary(90, 32, 4);
  const MatchBlock block = BlockOf({0}, d.rows);
  KeepRules rules;
  rules.best = 3;
  rules.exclusion = 5;
  cv::Mat1f full = HammingDistances(d);
  SequenceDistancesInPlace(full, 4, {0}, {0});
  NormalizeByMax(full);  // one traversal: the block is the whole matrix, same divisor
  BoundedOptions options;
  options.sequence_length = 4;
  options.range_rows = 5;
  float max_distance = 0;
  ExpectSame(BoundedMatches(d, block, rules, options, max_distance),
             MatchesFromMatrix(full, block, rules), 1.0f);
}

TEST(BoundedMatches, VectorDescriptorsUseL2) {
  cv::Mat d(60, 16, CV_32F);
  cv::RNG(5).fill(d, cv::RNG::UNIFORM, 0.0, 1.0);
  const MatchBlock block = BlockOf({0, 30}, d.rows);
  KeepRules rules;
  rules.best = 2;
  rules.one_traversal = false;
  float max_distance = 0;
  const std::vector<Match> got = BoundedMatches(d, block, rules, {}, max_distance);
  ASSERT_EQ(got.size(), 60u);
  for (const Match& m : got) {
    const float direct = static_cast<float>(cv::norm(d.row(30 + m.query), d.row(m.reference)));
    EXPECT_NEAR(m.distance * max_distance, direct, 1e-4);
  }
}

// L2 rows with sequences, in every direction: the same kept matches as the dense matrix of the
// separate pieces, distances within float rounding (the sums are formed in the same order,
// from each range's first row instead of the traversal's).
TEST(BoundedMatches, VectorDescriptorsWithSequencesEqualTheDenseMatrix) {
  cv::Mat d(130, 24, CV_32F);
  cv::RNG(8).fill(d, cv::RNG::UNIFORM, 0.0, 1.0);
  const std::vector<int> starts = {0, 60};
  const MatchBlock block = BlockOf(starts, d.rows);
  KeepRules rules;
  rules.best = 3;
  rules.one_traversal = false;
  for (auto dir :
       {SequenceDirection::kForward, SequenceDirection::kReverse, SequenceDirection::kBoth}) {
    SCOPED_TRACE(static_cast<int>(dir));
    cv::Mat1f full = L2Distances(d);
    SequenceDistancesInPlace(full, 6, starts, starts, dir);
    float block_max = 0;
    std::vector<Match> expected;
    for (int q = 0; q < block.query_count; ++q) {
      const int row = block.query_first + q;
      for (int j = 0; j < block.reference_count; ++j)
        if (std::isfinite(full(row, j))) block_max = std::max(block_max, full(row, j));
      for (const Match& m : SortedRow(full, row, q, 0, block.reference_count, rules))
        expected.push_back(m);
    }
    BoundedOptions options;
    options.sequence_length = 6;
    options.direction = dir;
    options.range_rows = 9;
    float max_distance = 0;
    const std::vector<Match> got = BoundedMatches(d, block, rules, options, max_distance);
    EXPECT_NEAR(max_distance, block_max, 1e-6 * block_max);
    ExpectSame(got, expected, 1.0f / block_max);
  }
}

// Approximate candidates on planted near-duplicates, with each engine of the build: every
// query's duplicate found first, and every kept distance is the exact one of its pair.
TEST(ApproximateMatches, FindsPlantedDuplicatesWithExactScores) {
  const int n = 2000;
  cv::Mat refs = RandomBinary(n, 32, 6);
  cv::Mat queries = refs.clone();
  std::mt19937 rng(7);
  for (int i = 0; i < n; ++i)
    for (int f = 0; f < 6; ++f) {
      const int bit = static_cast<int>(rng() % 256);
      queries.at<std::uint8_t>(i, bit / 8) ^= static_cast<std::uint8_t>(1 << (bit % 8));
    }
  cv::Mat d;
  cv::vconcat(refs, queries, d);
  const MatchBlock block = BlockOf({0, n}, d.rows);
  KeepRules rules;
  rules.best = 3;
  rules.one_traversal = false;
  for (const std::string engine : {"flann", "hnsw", "ivf"}) {
    if (!ApproximateEngineAvailable(engine)) continue;
    SCOPED_TRACE(engine);
    ApproximateOptions approximate;
    approximate.engine = engine;
    approximate.checks = 128;
    float max_distance = 0;
    const std::vector<Match> got =
        ApproximateMatches(d, block, rules, {}, approximate, max_distance);
    int found = 0;
    for (const Match& m : got) {
      const float exact = static_cast<float>(
          HammingDistance(d.ptr<std::uint8_t>(n + m.query), d.ptr<std::uint8_t>(m.reference), 32));
      EXPECT_NEAR(m.distance * max_distance, exact, 1e-3);
      if (m.rank == 1 && m.reference == m.query) ++found;
    }
    EXPECT_GE(found, 0.95 * n);
  }
}

// Sequence_partial skip and ahead, the ratio score and the L1 distance of SAD rows: the fused
// run against the dense matrix of the tested pieces, selected and scored by brute force (empty
// cells never kept; the ratio of a kept match over the best finite candidate more than the
// window away). Ahead's early cells come from rows a range computes past its end.
TEST(BoundedMatches, SkipAndAheadCellsAndRatioScoresEqualBruteForce) {
  const cv::Mat d = RandomBinary(120, 64, 9);
  for (const SequencePartial partial : {SequencePartial::kSkip, SequencePartial::kAhead})
    for (int traversals : {1, 2}) {
      const std::vector<int> starts =
          traversals == 1 ? std::vector<int>{0} : std::vector<int>{0, 50};
      const MatchBlock block = BlockOf(starts, d.rows);
      KeepRules rules;
      rules.best = 3;
      rules.exclusion = 10;
      rules.one_traversal = block.one_traversal;
      rules.score.kind = MatchScore::kRatio;
      rules.score.window = 4;
      for (auto dir :
           {SequenceDirection::kForward, SequenceDirection::kReverse, SequenceDirection::kBoth}) {
        const int L = 6;
        SCOPED_TRACE("traversals " + std::to_string(traversals) + " partial " + EnumName(partial) +
                     " direction " + std::to_string(static_cast<int>(dir)));
        cv::Mat1f full = L1Distances(d);
        SequenceDistancesInPlace(full, L, starts, starts, dir, 0, partial);
        float block_max = 0;
        std::vector<Match> expected;
        for (int q = 0; q < block.query_count; ++q) {
          const int row = block.query_first + q;
          std::vector<std::pair<float, int>> all;
          for (int j = 0; j < block.reference_count; ++j) {
            const float v = full(row, block.reference_first + j);
            if (!std::isfinite(v)) continue;
            block_max = std::max(block_max, v);
            if (!rules.one_traversal || j <= q - rules.exclusion) all.emplace_back(v, j);
          }
          std::sort(all.begin(), all.end());
          for (int r = 0; r < std::min<int>(rules.best, static_cast<int>(all.size())); ++r) {
            float rival = std::numeric_limits<float>::infinity();
            for (const auto& [v, j] : all)
              if (std::abs(j - all[r].second) > rules.score.window) rival = std::min(rival, v);
            const float ratio = std::isfinite(rival) && rival > 0 ? all[r].first / rival : 1.0f;
            expected.push_back({q, all[r].second, all[r].first, r + 1, ratio});
          }
        }
        for (const int tile : {-1, 5}) {
          SCOPED_TRACE("tile " + std::to_string(tile));
          BoundedOptions options;
          options.metric = Metric::kL1;
          options.sequence_length = L;
          options.direction = dir;
          options.partial = partial;
          options.range_rows = 7;
          options.tile_columns = tile;  // along diagonals: tiles of 2 L = 12 columns
          float max_distance = 0;
          const std::vector<Match> got = BoundedMatches(d, block, rules, options, max_distance);
          EXPECT_FLOAT_EQ(max_distance, block_max);
          ExpectSame(got, expected, 1.0f / block_max);
          for (size_t k = 0; k < got.size() && k < expected.size(); ++k)
            EXPECT_NEAR(got[k].score, expected[k].score, 1e-5) << k;
          // The first L - 1 queries of a traversal have no complete sequence along diagonals.
          if (dir == SequenceDirection::kForward && traversals == 2) {
            const auto first = std::min_element(got.begin(), got.end(),
                                                [](auto& a, auto& b) { return a.query < b.query; });
            ASSERT_NE(first, got.end());
            // skip: none before L - 1; ahead: the first query is answered.
            EXPECT_EQ(first->query, partial == SequencePartial::kSkip ? L - 1 : 0);
          }
        }
      }
    }
}

}  // namespace
}  // namespace openable
