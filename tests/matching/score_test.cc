// Match scores (matching/score.h): the distance and the ratio against a brute-force definition
// written here, on hand-made rows (ties, windows, no rival, a rival at 0, non-finite cells)
// and on random rows; sparse candidates agree with dense rows.
#include "matching/score.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace openable {
namespace {

const float kInf = std::numeric_limits<float>::infinity();

// The definition: the best column is the smallest finite distance (lowest column on ties);
// its ratio is its distance over the smallest finite distance more than `window` columns away
// (1 when there is none or it is 0).
float BruteRatio(const std::vector<float>& row, int window, int* best_out = nullptr) {
  int best = -1;
  for (int c = 0; c < static_cast<int>(row.size()); ++c)
    if (std::isfinite(row[c]) && (best < 0 || row[c] < row[best])) best = c;
  if (best_out) *best_out = best;
  if (best < 0) return std::nanf("");
  bool found = false;
  float rival = 0;
  for (int c = 0; c < static_cast<int>(row.size()); ++c) {
    if (std::abs(c - best) <= window || !std::isfinite(row[c])) continue;
    if (!found || row[c] < rival) rival = row[c], found = true;
  }
  if (!found || rival == 0) return 1.0f;
  return row[best] / rival;
}

float Dense(const std::vector<float>& row, MatchScore s, int window) {
  const int best = BestCandidate(row.data(), static_cast<int>(row.size()));
  return ScoreOfCandidate(row.data(), static_cast<int>(row.size()), best, {s, window});
}

TEST(MatchScore, HandWorkedRows) {
  // Best 0.2 at column 3; window 1 hides columns 2-4; the rival is 0.5 at column 0: 0.4.
  const std::vector<float> row = {0.5f, 0.9f, 0.25f, 0.2f, 0.3f, 0.8f};
  EXPECT_EQ(BestCandidate(row.data(), 6), 3);
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kRatio, 1), 0.2f / 0.5f);
  // Window 0: the neighbour 0.25 is a rival: 0.8.
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kRatio, 0), 0.2f / 0.25f);
  // Window 5 hides every column: no rival, 1.
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kRatio, 5), 1.0f);
  // The distance score is the distance.
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kDistance, 1), 0.2f);
}

TEST(MatchScore, TiesAndZeros) {
  // Two equal minima far apart: the lower column is best and the other its rival: ratio 1.
  const std::vector<float> tie = {0.7f, 0.3f, 0.9f, 0.9f, 0.9f, 0.3f};
  EXPECT_EQ(BestCandidate(tie.data(), 6), 1);
  EXPECT_FLOAT_EQ(Dense(tie, MatchScore::kRatio, 2), 1.0f);
  // A best at 0 with a positive rival: 0 (certain); a rival at 0 too: 1 (nothing to tell).
  const std::vector<float> zero = {0.0f, 0.4f, 0.4f, 0.5f};
  EXPECT_FLOAT_EQ(Dense(zero, MatchScore::kRatio, 1), 0.0f);
  const std::vector<float> zeros = {0.0f, 0.4f, 0.4f, 0.0f};
  EXPECT_FLOAT_EQ(Dense(zeros, MatchScore::kRatio, 1), 1.0f);
}

TEST(MatchScore, NonFiniteCellsAreNeitherCandidatesNorRivals) {
  const std::vector<float> row = {kInf, kInf, 0.3f, 0.6f, kInf, std::nanf(""), 0.5f};
  EXPECT_EQ(BestCandidate(row.data(), 7), 2);
  // Window 0: rivals 0.6 (col 3) and 0.5 (col 6): 0.3 / 0.5.
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kRatio, 0), 0.3f / 0.5f);
  // Window 3: only col 6 is outside and finite.
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kRatio, 3), 0.3f / 0.5f);
  // Window 4: nothing finite outside: 1.
  EXPECT_FLOAT_EQ(Dense(row, MatchScore::kRatio, 4), 1.0f);
  const std::vector<float> empty = {kInf, kInf};
  EXPECT_EQ(BestCandidate(empty.data(), 2), -1);
}

// Random rows with repeated values (ties), some +inf, against the brute force; and the same
// row as sparse candidates in shuffled order.
TEST(MatchScore, RandomRowsMatchBruteForceDenseAndSparse) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> level(0, 30), len(1, 60), win(0, 12), chance(0, 9);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<float> row(static_cast<size_t>(len(rng)));
    for (float& v : row) v = chance(rng) == 0 ? kInf : level(rng) / 30.0f;
    const int window = win(rng);
    int best = -1;
    const float expected = BruteRatio(row, window, &best);
    ASSERT_EQ(BestCandidate(row.data(), static_cast<int>(row.size())), best);
    if (best < 0) continue;
    ASSERT_FLOAT_EQ(Dense(row, MatchScore::kRatio, window), expected) << "trial " << trial;
    std::vector<std::pair<float, int>> sparse;
    for (int c = 0; c < static_cast<int>(row.size()); ++c)
      if (std::isfinite(row[c])) sparse.emplace_back(row[c], c);
    std::shuffle(sparse.begin(), sparse.end(), rng);
    size_t at = 0;
    while (sparse[at].second != best) ++at;
    ASSERT_FLOAT_EQ(ScoreOfCandidate(sparse, at, {MatchScore::kRatio, window}), expected);
    ASSERT_FLOAT_EQ(ScoreOfCandidate(sparse, at, {MatchScore::kDistance, window}), row[best]);
  }
}

TEST(MatchScore, NamesParse) {
  EXPECT_EQ(ParseEnum<MatchScore>("ratio", "Match_score"), MatchScore::kRatio);
  EXPECT_EQ(EnumName(MatchScore::kDistance), "distance");
  EXPECT_ANY_THROW(ParseEnum<MatchScore>("confidence", "Match_score"));
}

}  // namespace
}  // namespace openable
