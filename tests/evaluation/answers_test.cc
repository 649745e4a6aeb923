// The answers of a matrix without ground truth (OpenABLE/evaluation/answers.h): each query's
// best match and score against a brute-force reading of the matrix (tests/tools), the
// acceptance by Match_threshold and the confirmation by Match_consistency against the matches
// file's rule (AcceptedMatches over rank-1 matches, matching/bounded.h) and against the
// operating point the per-query protocol counts with ground truth.
#include "OpenABLE/evaluation/answers.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "OpenABLE/base/error.h"
#include "matching/bounded.h"
#include "tests/tools/brute_per_query.h"

namespace openable {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Two traversals of `n` frames (references rows/columns 0..n-1, queries after them): random
// distances, query q's place (reference q) small for most queries, a few cells without a
// value, and the first two queries without any.
cv::Mat1f TwoTraversals(int n, unsigned seed) {
  cv::Mat1f m(2 * n, 2 * n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.4f, 1.0f);
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) m(r, c) = u(rng);
  for (int q = 0; q < n; ++q) {
    if (q % 7 != 3) m(n + q, q) = 0.05f + 0.004f * static_cast<float>(q % 50);
    if (q % 11 == 5) m(n + q, (q + 3) % n) = kInf;
  }
  for (int c = 0; c < n; ++c) m(n, c) = m(n + 1, c) = kInf;
  return m;
}

std::vector<Match> RankOneMatches(const QueryAnswers& a) {
  std::vector<Match> out;
  for (int q = 0; q < static_cast<int>(a.best.size()); ++q)
    if (a.best[q] >= 0) out.push_back({q, a.best[q], a.distance[q], 1, a.score[q]});
  return out;
}

TEST(Answers, BestMatchesAndScoresAreThoseOfABruteForceReading) {
  const int n = 120;
  const cv::Mat1f m = TwoTraversals(n, 3);
  const cv::Mat1f block = m(cv::Rect(0, n, n, n));
  for (const MatchScore kind : {MatchScore::kDistance, MatchScore::kRatio}) {
    SCOPED_TRACE(EnumName(kind));
    EvaluationOptions o;
    o.score.kind = kind;
    o.score.window = 4;
    o.accept_threshold = kind == MatchScore::kRatio ? 0.5 : 0.3;
    const QueryAnswers a = AnswersOfMatrix(m, EvaluationLayout::TwoTraversals(n, n), o);
    const testing::BruteFigures brute = testing::BrutePerQuery(
        block, std::vector<std::vector<int>>(n), false, 0, 0, kind == MatchScore::kRatio, 4);
    ASSERT_EQ(a.best.size(), static_cast<std::size_t>(n));
    int answered = 0, accepted = 0;
    for (int q = 0; q < n; ++q) {
      const testing::BruteQuery& b = brute.queries[q];
      EXPECT_EQ(a.best[q], b.best) << q;
      if (!b.answered) {
        EXPECT_EQ(a.accepted[q], 0) << q;
        continue;
      }
      ++answered;
      EXPECT_EQ(a.distance[q], block(q, b.best)) << q;
      EXPECT_NEAR(a.score[q], b.score, 1e-6) << q;
      const bool within = static_cast<float>(b.score) <= o.accept_threshold;
      accepted += within;
      EXPECT_EQ(a.accepted[q], within ? 1 : 0) << q;
      // Without Match_consistency every accepted answer is confirmed.
      EXPECT_EQ(a.confirmed[q], a.accepted[q]) << q;
    }
    EXPECT_EQ(a.queries, n);
    EXPECT_EQ(a.answered, answered);
    EXPECT_EQ(answered, n - 2);
    EXPECT_EQ(a.Accepted(), accepted);
    EXPECT_GT(accepted, n / 2);
    EXPECT_LT(accepted, answered);
  }
}

TEST(Answers, ConfirmationIsTheMatchesFilesRuleAndTheEvaluationsOperatingPoint) {
  const int n = 150;
  const cv::Mat1f m = TwoTraversals(n, 11);
  EvaluationOptions o;
  o.score.kind = MatchScore::kRatio;
  o.accept_threshold = 0.6;
  o.accept_consistency = 1;
  o.agreement.sequence_length = 1;
  o.agreement.partial = SequencePartial::kScale;
  const EvaluationLayout layout = EvaluationLayout::TwoTraversals(n, n);
  const QueryAnswers a = AnswersOfMatrix(m, layout, o);
  // The matches file's rule over the same rank-1 matches: the threshold alone, then confirmed.
  const std::vector<Match> matches = RankOneMatches(a);
  AgreementOptions agreement = o.agreement;
  agreement.partners = 1;
  EXPECT_EQ(a.accepted, AcceptedMatches(matches, n, o.accept_threshold));
  EXPECT_EQ(a.confirmed, AcceptedMatches(matches, n, o.accept_threshold, &agreement));
  // Confirmation keeps some and refuses some (the queries whose place is not the smallest).
  EXPECT_LT(a.Confirmed(), a.Accepted());
  EXPECT_GT(a.Confirmed(), 0);
  for (int q = 0; q < n; ++q) EXPECT_LE(a.confirmed[q], a.accepted[q]) << q;
  // With ground truth the evaluation's operating point holds the same answers.
  GroundTruth truth;
  truth.references = n;
  truth.matches.resize(n);
  for (int q = 0; q < n; ++q) truth.matches[q] = {q};
  const PerQueryResult p = EvaluatePerQuery(m, layout, truth, o);
  EXPECT_EQ(p.best, a.best);
  EXPECT_EQ(p.accepted, a.confirmed);
  EXPECT_EQ(p.operating_point.tp + p.operating_point.fp, a.Confirmed());
}

TEST(Answers, NothingIsAcceptedWithoutAThresholdOrWhenUntrusted) {
  const int n = 40;
  const cv::Mat1f m = TwoTraversals(n, 5);
  EvaluationOptions o;
  const QueryAnswers none = AnswersOfMatrix(m, EvaluationLayout::TwoTraversals(n, n), o);
  EXPECT_EQ(none.Accepted(), 0);
  EXPECT_EQ(none.Confirmed(), 0);
  EXPECT_EQ(none.answered, n - 2);
  o.accept_threshold = 1.0;
  EXPECT_EQ(AnswersOfMatrix(m, EvaluationLayout::TwoTraversals(n, n), o).Accepted(), n - 2);
  o.accept_none = true;
  const QueryAnswers untrusted = AnswersOfMatrix(m, EvaluationLayout::TwoTraversals(n, n), o);
  EXPECT_EQ(untrusted.Accepted(), 0);
  EXPECT_EQ(untrusted.best, none.best);  // the answers are still there
}

TEST(Answers, OneSequenceTakesTheFramesAtLeastTheExclusionBack) {
  cv::Mat1f m(6, 6, 1.0f);
  m(4, 0) = 0.2f;
  m(4, 3) = 0.1f;  // inside the exclusion of 2: not a candidate of query 4
  m(5, 1) = 0.3f;
  EvaluationOptions o;
  o.exclusion = 2;
  o.accept_threshold = 0.25;
  const QueryAnswers a = AnswersOfMatrix(m, EvaluationLayout::LoopClosure(6), o);
  EXPECT_EQ(a.best, (std::vector<int>{-1, -1, 0, 0, 0, 1}));
  EXPECT_EQ(a.queries, 4);  // queries 0 and 1 have no candidate
  EXPECT_EQ(a.accepted, (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0}));
}

TEST(Answers, CandidatesChosenElsewhereAreAcceptedByTheSameRule) {
  const EvaluationLayout layout = EvaluationLayout::QueryReference(3, 10);
  EvaluationOptions o;
  o.accept_threshold = 0.5;
  const QueryAnswers a =
      AnswersOfCandidates(layout, {{{4, 0.3f, 0.3f}, {7, 0.4f, 0.4f}}, {}, {{2, 0.6f, 0.6f}}}, o);
  EXPECT_EQ(a.best, (std::vector<int>{4, -1, 2}));
  EXPECT_EQ(a.answered, 2);
  EXPECT_EQ(a.accepted, (std::vector<std::uint8_t>{1, 0, 0}));
  EXPECT_THROW(AnswersOfCandidates(layout, {{}, {}}, o), std::logic_error);
}

TEST(Answers, BadInputIsRefused) {
  const cv::Mat1f m(4, 4, 0.5f);
  EvaluationOptions o;
  EXPECT_THROW(AnswersOfMatrix(m, EvaluationLayout::QueryReference(5, 4), o), std::logic_error);
  o.score.kind = MatchScore::kRatio;
  o.score.window = 4;
  EXPECT_THROW(AnswersOfMatrix(m, EvaluationLayout::QueryReference(4, 4), o), InputError);
  std::vector<std::uint8_t> accepted, confirmed;
  EXPECT_THROW(AcceptAnswers({1, 2}, {0.5f}, o, accepted, confirmed), std::logic_error);
}

}  // namespace
}  // namespace openable
