// The two protocols on hand-made matrices; every expected figure is worked out by hand in the
// comments (docs/evaluation.md gives the definitions).
#include "OpenABLE/evaluation/metrics.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"
#include "tests/tools/brute_per_query.h"

namespace openable {
namespace {

GroundTruth Truth(std::vector<std::vector<int>> matches, int references) {
  GroundTruth t;
  t.matches = std::move(matches);
  t.references = references;
  return t;
}

// 4 queries x 5 references.
//   q0: best c1 (0.10), truth {1}: correct
//   q1: best c2 (0.20), truth {4}: wrong with tolerance 1 (|2 - 4| = 2)
//   q2: best c3 (0.35), no truth: a negative query, any accepted answer is false
//   q3: best c4 (0.45), truth {3}: correct with tolerance 1
cv::Mat1f QueryReferenceBlock() {
  return (cv::Mat1f(4, 5) << 0.9f, 0.1f, 0.5f, 0.7f, 0.8f,  //
          0.3f, 0.6f, 0.2f, 0.9f, 0.4f,                     //
          0.5f, 0.5f, 0.6f, 0.35f, 0.9f,                    //
          0.8f, 0.7f, 0.6f, 0.5f, 0.45f);
}

TEST(PerQuery, HandWorkedQueryReferenceExample) {
  EvaluationOptions o;
  o.tolerance = 1;
  const PerQueryResult r =
      EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                       Truth({{1}, {4}, {}, {3}}, 5), o);
  EXPECT_EQ(r.queries, 4);
  EXPECT_EQ(r.positive_queries, 3);
  EXPECT_EQ(r.best, (std::vector<int>{1, 2, 3, 4}));
  // Accepted in order 0.10 (TP), 0.20 (FP), 0.35 (FP), 0.45 (TP); recall over 3 positives.
  ASSERT_EQ(r.curve.size(), 4u);
  const double p[] = {1.0, 0.5, 1.0 / 3, 0.5}, rc[] = {1.0 / 3, 1.0 / 3, 1.0 / 3, 2.0 / 3};
  const double thr[] = {0.1, 0.2, 0.35, 0.45};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(r.curve[i].precision, p[i], 1e-12) << i;
    EXPECT_NEAR(r.curve[i].recall, rc[i], 1e-12) << i;
    EXPECT_NEAR(r.curve[i].threshold, thr[i], 1e-6) << i;
  }
  // AUC = 1 x 1/3 + 0.5 x 0 + 1/3 x 0 + 0.5 x 1/3 = 0.5.
  EXPECT_NEAR(r.auc, 0.5, 1e-12);
  EXPECT_NEAR(r.recall_at_100p, 1.0 / 3, 1e-12);
  // F1 at the last point: 2 x 0.5 x 2/3 / (0.5 + 2/3) = 4/7, the largest.
  EXPECT_NEAR(r.max_f1, 4.0 / 7, 1e-12);
  EXPECT_NEAR(r.max_f1_threshold, 0.45, 1e-6);
  // R@1: q0 and q3 of 3 positives; R@5: q1's c4 is among its 5 candidates.
  EXPECT_NEAR(r.recall_at_1, 2.0 / 3, 1e-12);
  EXPECT_NEAR(r.recall_at_5, 1.0, 1e-12);
  EXPECT_NEAR(r.recall_at_10, 1.0, 1e-12);
}

// Match_consistency by hand: 30 queries, query q's true place is reference q + 100. Every
// answer is right (distance 0.5) but for query 15, whose best match is reference 900 (0.2,
// wrong), and query 25, right but at 0.95, above the threshold 0.9. With L = 1 (partners 10
// queries apart, tolerance 3; queries 0-9 take the query 10 after them): the score alone
// accepts 29 answers, one wrong (15); with one partner, 5 (its partner 15 is wrong) and 15
// lose too: 27 accepted, all right.
TEST(PerQuery, ConsistencyAcceptanceByHand) {
  cv::Mat1f m(30, 1000, 1.0f);
  std::vector<std::vector<int>> truth(30);
  for (int q = 0; q < 30; ++q) {
    m(q, q + 100) = 0.5f;
    truth[q] = {q + 100};
  }
  m(15, 900) = 0.2f;
  m(25, 125) = 0.95f;
  EvaluationOptions o;
  o.tolerance = 2;
  o.accept_threshold = 0.9;
  const auto layout = EvaluationLayout::QueryReference(30, 1000);
  const PerQueryResult alone = EvaluatePerQuery(m, layout, Truth(truth, 1000), o);
  EXPECT_EQ(alone.operating_point.tp, 28);
  EXPECT_EQ(alone.operating_point.fp, 1);
  EXPECT_NEAR(alone.operating_point.precision, 28.0 / 29, 1e-12);
  o.accept_consistency = 1;
  o.agreement.sequence_length = 1;
  o.agreement.partial = SequencePartial::kScale;
  const PerQueryResult confirmed = EvaluatePerQuery(m, layout, Truth(truth, 1000), o);
  EXPECT_EQ(confirmed.operating_point.tp, 27);
  EXPECT_EQ(confirmed.operating_point.fp, 0);
  EXPECT_DOUBLE_EQ(confirmed.operating_point.precision, 1.0);
  EXPECT_NEAR(confirmed.operating_point.recall, 27.0 / 30, 1e-12);
  for (int q : {5, 15, 25}) EXPECT_EQ(confirmed.accepted[q], 0) << q;
  EXPECT_EQ(confirmed.accepted[6], 1);
  // The curve does not change: the consistency only decides the operating point.
  EXPECT_EQ(confirmed.auc, alone.auc);
  // An untrusted auto run accepts nothing.
  o.accept_none = true;
  const PerQueryResult none = EvaluatePerQuery(m, layout, Truth(truth, 1000), o);
  EXPECT_EQ(none.operating_point.tp + none.operating_point.fp, 0);
  EXPECT_DOUBLE_EQ(none.operating_point.precision, 1.0);
}

TEST(PerQuery, ToleranceZeroAndTwoChangeOnlyTheAmbiguousQuery) {
  EvaluationOptions o;
  o.tolerance = 0;
  PerQueryResult r = EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), o);
  EXPECT_NEAR(r.recall_at_1, 1.0 / 3, 1e-12);  // q3's best c4 is 1 away from 3
  o.tolerance = 2;
  r = EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                       Truth({{1}, {4}, {}, {3}}, 5), o);
  EXPECT_NEAR(r.recall_at_1, 1.0, 1e-12);
  // Now 0.10 TP, 0.20 TP, 0.35 FP, 0.45 TP: AUC = 1 x 2/3 + 0.75 x 1/3 = 11/12.
  EXPECT_NEAR(r.auc, 11.0 / 12, 1e-12);
  EXPECT_NEAR(r.recall_at_100p, 2.0 / 3, 1e-12);
}

// Loop closure over 6 frames, exclusion 2: the candidates of q are j <= q - 2.
//   q2: {0}; q3: {0, 1}; q4: {0, 1, 2}; q5: {0, 1, 2, 3}; q0 and q1 have none.
// Truth: (4, 0), (5, 1) and (3, 2), the last inside the exclusion window.
TEST(PerQuery, LoopClosureUsesEarlierFramesOutsideTheExclusionWindow) {
  cv::Mat1f m(6, 6, 1.0f);
  const float lower[6][4] = {
      {}, {}, {0.6f}, {0.5f, 0.9f}, {0.2f, 0.7f, 0.8f}, {0.9f, 0.85f, 0.3f, 0.4f}};
  for (int q = 2; q < 6; ++q)
    for (int j = 0; j <= q - 2; ++j) m(q, j) = m(j, q) = lower[q][j];
  for (int q = 0; q < 6; ++q) m(q, q) = 0.0f;  // the diagonal is never a candidate
  EvaluationOptions o;
  o.exclusion = 2;
  o.tolerance = 0;
  const PerQueryResult r = EvaluatePerQuery(m, EvaluationLayout::LoopClosure(6),
                                            Truth({{}, {}, {}, {2}, {0}, {1}}, 6), o);
  EXPECT_EQ(r.queries, 4);
  EXPECT_EQ(r.positive_queries, 2);  // q4, q5 (q3's only match is excluded)
  EXPECT_EQ(r.truth_pairs_outside_candidates, 1);
  EXPECT_EQ(r.best, (std::vector<int>{-1, -1, 0, 0, 0, 2}));
  // 0.2 TP (q4), 0.3 FP (q5), 0.5 FP (q3, negative), 0.6 FP (q2): AUC = 1 x 0.5.
  ASSERT_EQ(r.curve.size(), 4u);
  EXPECT_NEAR(r.curve[3].precision, 0.25, 1e-12);
  EXPECT_NEAR(r.auc, 0.5, 1e-12);
  EXPECT_NEAR(r.recall_at_100p, 0.5, 1e-12);
  EXPECT_NEAR(r.max_f1, 2.0 / 3, 1e-12);
  EXPECT_NEAR(r.recall_at_1, 0.5, 1e-12);
  // q5's candidates by distance: c2 0.3, c3 0.4, c1 0.85: its match c1 is third.
  EXPECT_NEAR(r.recall_at_5, 1.0, 1e-12);
}

TEST(PerQuery, TiesKeepTheLowerColumnAndShareOneCurvePoint) {
  const cv::Mat1f m = (cv::Mat1f(2, 3) << 0.4f, 0.2f, 0.2f, 0.2f, 0.9f, 0.9f);
  EvaluationOptions o;
  o.tolerance = 0;
  const PerQueryResult r =
      EvaluatePerQuery(m, EvaluationLayout::QueryReference(2, 3), Truth({{2}, {0}}, 3), o);
  EXPECT_EQ(r.best, (std::vector<int>{1, 0}));
  ASSERT_EQ(r.curve.size(), 1u);  // both best distances are 0.2
  EXPECT_EQ(r.curve[0].tp, 1);
  EXPECT_EQ(r.curve[0].fp, 1);
  EXPECT_NEAR(r.recall_at_100p, 0.0, 1e-12);
}

TEST(PerQuery, TwoTraversalLayoutReadsTheLowerLeftBlock) {
  // 2 reference frames then 2 query frames; the block is rows 2-3, columns 0-1.
  const cv::Mat1f m = (cv::Mat1f(4, 4) << 0, 9, 0.3f, 0.1f,  //
                       9, 0, 0.2f, 0.8f,                     //
                       0.3f, 0.2f, 0, 9,                     //
                       0.1f, 0.8f, 9, 0);
  const PerQueryResult r = EvaluatePerQuery(m, EvaluationLayout::TwoTraversals(2, 2),
                                            Truth({{1}, {0}}, 2), EvaluationOptions());
  EXPECT_EQ(r.best, (std::vector<int>{1, 0}));
  EXPECT_NEAR(r.recall_at_1, 1.0, 1e-12);
}

// Answers chosen elsewhere (geometric verification): 4 queries of 4 references, tolerance 0,
// query q's true match is reference q. q0 answers 0 (right, score 0.2); q1 has no answer; q2
// answers 0 (wrong, score 0.1) then 2; q3 answers 3 (right, score 0.3). By hand: the curve
// over scores 0.1, 0.2, 0.3 is (P 0, R 0), (P 1/2, R 1/4), (P 2/3, R 1/2); AUC = 1/2 x 1/4 +
// 2/3 x 1/4; R@1 = 2/4, R@5 = 3/4 (q2's second answer).
TEST(PerQuery, AnswersChosenElsewhere) {
  EvaluationOptions o;
  o.tolerance = 0;
  const std::vector<std::vector<Answer>> answers = {
      {{0, 0.5f, 0.2f}}, {}, {{0, 0.4f, 0.1f}, {2, 0.6f, 0.7f}}, {{3, 0.3f, 0.3f}}};
  const PerQueryResult r = EvaluateAnswers(EvaluationLayout::QueryReference(4, 4),
                                           Truth({{0}, {1}, {2}, {3}}, 4), answers, o);
  EXPECT_EQ(r.queries, 4);
  EXPECT_EQ(r.positive_queries, 4);
  EXPECT_EQ(r.unanswered, 1);
  EXPECT_EQ(r.best, (std::vector<int>{0, -1, 0, 3}));
  ASSERT_EQ(r.curve.size(), 3u);
  EXPECT_NEAR(r.curve[0].precision, 0.0, 1e-12);
  EXPECT_NEAR(r.curve[1].precision, 0.5, 1e-12);
  EXPECT_NEAR(r.curve[2].recall, 0.5, 1e-12);
  EXPECT_NEAR(r.auc, 0.5 * 0.25 + 2.0 / 3.0 * 0.25, 1e-12);
  EXPECT_NEAR(r.recall_at_1, 0.5, 1e-12);
  EXPECT_NEAR(r.recall_at_5, 0.75, 1e-12);
  EXPECT_NEAR(r.recall_at_100p, 0.0, 1e-12);  // the first answer accepted is wrong
  // An answer outside the query's candidates is a programming error.
  EXPECT_THROW(EvaluateAnswers(EvaluationLayout::QueryReference(4, 4),
                               Truth({{0}, {1}, {2}, {3}}, 4), {{{7, 0, 0}}, {}, {}, {}}, o),
               std::logic_error);
}

// ABLE-P protocol with 3 thresholds (0, 0.5, 1) on the query-reference block above; truth
// cells (0,1), (1,4), (3,3); a detection counts within `vicinity` rows and columns of one.
AblePResult AblePOfTheBlock(int vicinity) {
  EvaluationOptions o;
  o.able_thresholds = 3;
  o.vicinity = vicinity;
  return EvaluateAbleP(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                       Truth({{1}, {4}, {}, {3}}, 5), o);
}

TEST(AbleP, HandWorkedVicinityZero) {
  const AblePResult r = AblePOfTheBlock(0);
  EXPECT_EQ(r.candidate_cells, 20);
  EXPECT_EQ(r.truth_cells, 3);
  ASSERT_EQ(r.curve.size(), 3u);
  // theta 0: nothing detected (precision 1 by convention, recall 0).
  EXPECT_EQ(r.curve[0].tp + r.curve[0].fp, 0);
  EXPECT_NEAR(r.curve[0].precision, 1.0, 1e-12);
  EXPECT_NEAR(r.curve[0].recall, 0.0, 1e-12);
  // theta 0.5: 6 cells below (0.1, 0.3, 0.2, 0.4, 0.35, 0.45), 2 of them truth; (3,3) = 0.5 is
  // not below 0.5, so 2 of 3 truth cells are found.
  EXPECT_EQ(r.curve[1].tp, 2);
  EXPECT_EQ(r.curve[1].fp, 4);
  EXPECT_NEAR(r.curve[1].recall, 2.0 / 3, 1e-12);
  // theta 1: all 20 cells, 3 true.
  EXPECT_EQ(r.curve[2].tp, 3);
  EXPECT_EQ(r.curve[2].fp, 17);
  EXPECT_NEAR(r.curve[2].recall, 1.0, 1e-12);
  // AP = 100 x (1/3 x 2/3 + 3/20 x 1/3) = 100 x 49/180.
  EXPECT_NEAR(r.average_precision, 100.0 * 49 / 180, 1e-9);
}

TEST(AbleP, HandWorkedVicinityOne) {
  const AblePResult r = AblePOfTheBlock(1);
  // theta 0.5: each of the 6 detections is within one row and column of a truth cell; (3,3)
  // is found through its neighbour (2,3) = 0.35.
  EXPECT_EQ(r.curve[1].tp, 6);
  EXPECT_EQ(r.curve[1].fp, 0);
  EXPECT_NEAR(r.curve[1].recall, 1.0, 1e-12);
  // theta 1: 16 of the 20 cells lie in the union of the three 3x3 neighbourhoods.
  EXPECT_EQ(r.curve[2].tp, 16);
  EXPECT_EQ(r.curve[2].fp, 4);
  EXPECT_NEAR(r.average_precision, 100.0, 1e-9);
}

TEST(AbleP, LoopClosureCountsOnlyCandidateCells) {
  cv::Mat1f m(5, 5, 0.3f);
  EvaluationOptions o;
  o.exclusion = 2;
  o.vicinity = 0;
  // Candidates: (2,0), (3,0), (3,1), (4,0), (4,1), (4,2) = 6 cells; truth (4,1) and (1,0), the
  // second inside the window.
  const AblePResult r =
      EvaluateAbleP(m, EvaluationLayout::LoopClosure(5), Truth({{}, {0}, {}, {}, {1}}, 5), o);
  EXPECT_EQ(r.candidate_cells, 6);
  EXPECT_EQ(r.truth_cells, 1);
  // Every candidate is 0.3: 29/99 = 0.2929 detects nothing, 30/99 = 0.3030 detects all six;
  // then precision 1/6, recall 1.
  EXPECT_EQ(r.curve[29].tp + r.curve[29].fp, 0);
  EXPECT_EQ(r.curve[30].tp, 1);
  EXPECT_EQ(r.curve[30].fp, 5);
  EXPECT_NEAR(r.average_precision, 100.0 / 6, 1e-9);
}

TEST(EvaluationOptions, CheckNamesTheKey) {
  const std::pair<void (*)(EvaluationOptions&), const char*> cases[] = {
      {[](EvaluationOptions& o) { o.tolerance = -1; }, "Tolerance: -1"},
      {[](EvaluationOptions& o) { o.exclusion = 0; }, "Exclusion: 0"},
      {[](EvaluationOptions& o) { o.vicinity = -3; }, "Vicinity: -3"},
  };
  for (const auto& [change, key] : cases)
    EXPECT_NE(testing::CheckError<EvaluationOptions>(change).find(key), std::string::npos) << key;
}

// --- The ratio score ---------------------------------------------------------------------------

// The query-reference block above with the ratio, window 1: q0 best c1 0.10, rivals c3 0.7 and
// c4 0.8: 0.1 / 0.7; q1 best c2 0.20, rivals c0 0.3 and c4 0.4: 0.2 / 0.3; q2 best c3 0.35,
// rivals c0 0.5 and c1 0.5: 0.35 / 0.5 = 0.7; q3 best c4 0.45, rivals c0 0.8, c1 0.7, c2 0.6:
// 0.45 / 0.6 = 0.75. Order: q0 (TP), q1 (FP), q2 (FP), q3 (TP), as with the distance.
TEST(PerQueryRatio, HandWorkedQueryReferenceExample) {
  EvaluationOptions o;
  o.tolerance = 1;
  o.score.kind = MatchScore::kRatio;
  o.score.window = 1;
  const PerQueryResult r =
      EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                       Truth({{1}, {4}, {}, {3}}, 5), o);
  ASSERT_EQ(r.score.size(), 4u);
  EXPECT_FLOAT_EQ(r.score[0], 0.1f / 0.7f);
  EXPECT_FLOAT_EQ(r.score[1], 0.2f / 0.3f);
  EXPECT_FLOAT_EQ(r.score[2], 0.35f / 0.5f);
  EXPECT_FLOAT_EQ(r.score[3], 0.45f / 0.6f);
  EXPECT_EQ(r.best_distance[3], 0.45f);  // the distance is kept beside the score
  ASSERT_EQ(r.curve.size(), 4u);
  EXPECT_NEAR(r.curve[0].threshold, 0.1 / 0.7, 1e-6);
  EXPECT_NEAR(r.auc, 0.5, 1e-12);
}

// The ratio re-orders answers: a wrong best match with a close rival (ratio near 1) falls
// below a right one that stands out, although its distance is smaller.
TEST(PerQueryRatio, SeparatesWhatTheDistanceCannot) {
  // q0: best c0 0.10 (wrong, truth c4), rival c3 0.11: ratio 0.91.
  // q1: best c4 0.30 (right), rivals at 0.9: ratio 0.33.
  const cv::Mat1f m = (cv::Mat1f(2, 5) << 0.10f, 0.9f, 0.9f, 0.11f, 0.5f,  //
                       0.9f, 0.9f, 0.9f, 0.9f, 0.30f);
  EvaluationOptions o;
  o.tolerance = 0;
  const auto layout = EvaluationLayout::QueryReference(2, 5);
  const GroundTruth t = Truth({{4}, {4}}, 5);
  const PerQueryResult by_distance = EvaluatePerQuery(m, layout, t, o);
  EXPECT_EQ(by_distance.recall_at_100p, 0.0);  // the wrong answer comes first
  o.score.kind = MatchScore::kRatio;
  o.score.window = 1;
  const PerQueryResult by_ratio = EvaluatePerQuery(m, layout, t, o);
  EXPECT_NEAR(by_ratio.recall_at_100p, 0.5, 1e-12);
  EXPECT_NEAR(by_ratio.auc, 0.5, 1e-12);
}

// Random matrices with ties (few distinct levels) and skipped cells (+inf), in both layouts,
// against the brute force of tests/brute_per_query.h.
TEST(PerQueryRatio, RandomMatricesMatchBruteForce) {
  std::mt19937 rng(21);
  std::uniform_int_distribution<int> level(1, 12), chance(0, 14), pick(0, 59);
  const float inf = std::numeric_limits<float>::infinity();
  for (int trial = 0; trial < 60; ++trial) {
    const bool loop = trial % 2 == 0;
    const int n = 60;
    cv::Mat1f m(n, n);
    for (float& v : m) v = chance(rng) == 0 ? inf : level(rng) / 12.0f;
    for (int q = 0; q < 3; ++q) m.row(q).setTo(inf);  // unanswered queries (skip cells)
    std::vector<std::vector<int>> truth(n);
    for (int q = 0; q < n; ++q) {
      if (chance(rng) < 3) continue;  // a negative query
      const int c = loop ? (q >= 10 ? pick(rng) % (q - 9) : -1) : pick(rng);
      if (c >= 0) truth[q] = {c};
    }
    for (const bool ratio : {false, true}) {
      EvaluationOptions o;
      o.tolerance = 1;
      o.exclusion = 10;
      o.score.kind = ratio ? MatchScore::kRatio : MatchScore::kDistance;
      o.score.window = trial % 5;
      const EvaluationLayout layout =
          loop ? EvaluationLayout::LoopClosure(n) : EvaluationLayout::QueryReference(n, n);
      const PerQueryResult r = EvaluatePerQuery(m, layout, Truth(truth, n), o);
      const testing::BruteFigures b =
          testing::BrutePerQuery(m, truth, loop, o.exclusion, o.tolerance, ratio, o.score.window);
      for (int q = 0; q < n; ++q) {
        const testing::BruteQuery& e = b.queries[q];
        ASSERT_EQ(r.best[q], e.best) << "trial " << trial << " q " << q;
        if (e.answered) {
          ASSERT_FLOAT_EQ(r.score[q], static_cast<float>(e.score)) << q;
        }
        ASSERT_EQ(r.correct[q] != 0, e.correct) << q;
      }
      EXPECT_EQ(r.unanswered, b.unanswered);
      EXPECT_EQ(r.positive_queries, b.positives);
      EXPECT_NEAR(r.auc, b.auc, 1e-9) << "trial " << trial << " ratio " << ratio;
      EXPECT_NEAR(r.recall_at_100p, b.recall_at_100p, 1e-9) << "trial " << trial;
    }
  }
}

// A query whose every candidate is +inf gives no answer; a positive one still counts in the
// recall's denominator.
TEST(PerQuery, UnansweredQueriesLowerRecall) {
  const float inf = std::numeric_limits<float>::infinity();
  const cv::Mat1f m = (cv::Mat1f(2, 2) << inf, inf, 0.2f, 0.5f);
  EvaluationOptions o;
  o.tolerance = 0;
  const PerQueryResult r =
      EvaluatePerQuery(m, EvaluationLayout::QueryReference(2, 2), Truth({{0}, {0}}, 2), o);
  EXPECT_EQ(r.queries, 2);
  EXPECT_EQ(r.unanswered, 1);
  EXPECT_EQ(r.best, (std::vector<int>{-1, 0}));
  EXPECT_NEAR(r.recall_at_100p, 0.5, 1e-12);
  EXPECT_NEAR(r.recall_at_1, 0.5, 1e-12);
}

// The operating point of Match_threshold: the last curve point at or below it.
TEST(PerQuery, OperatingPointIsTheCurveAtTheAcceptThreshold) {
  EvaluationOptions o;
  o.tolerance = 1;
  o.accept_threshold = 0.3;  // accepts q0 (0.10, TP) and q1 (0.20, FP)
  PerQueryResult r = EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), o);
  ASSERT_TRUE(r.has_operating_point);
  EXPECT_EQ(r.operating_point.tp, 1);
  EXPECT_EQ(r.operating_point.fp, 1);
  EXPECT_NEAR(r.operating_point.precision, 0.5, 1e-12);
  EXPECT_NEAR(r.operating_point.recall, 1.0 / 3, 1e-12);
  EXPECT_EQ(r.operating_point.threshold, 0.3);
  o.accept_threshold = 0.05;  // nothing accepted: precision 1, recall 0
  r = EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                       Truth({{1}, {4}, {}, {3}}, 5), o);
  EXPECT_EQ(r.operating_point.tp + r.operating_point.fp, 0);
  EXPECT_EQ(r.operating_point.precision, 1.0);
  EXPECT_EQ(r.operating_point.recall, 0.0);
  o.accept_threshold = -1;
  EXPECT_FALSE(EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                                Truth({{1}, {4}, {}, {3}}, 5), o)
                   .has_operating_point);
}

TEST(PerQueryRatio, WindowAsLargeAsTheReferencesIsAnError) {
  EvaluationOptions o;
  o.score.kind = MatchScore::kRatio;
  o.score.window = 5;
  try {
    EvaluatePerQuery(QueryReferenceBlock(), EvaluationLayout::QueryReference(4, 5),
                     Truth({{1}, {4}, {}, {3}}, 5), o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Match_score_window: 5"), std::string::npos) << e.what();
  }
  o.score.window = -1;
  EXPECT_THROW(o.Check(), InputError);
}

// Warnings of an evaluation whose figures say little about the matrix (EvaluationWarnings).
// A 6 x 6 similarity of two aligned traversals: each query's own place is the most similar
// (0.9), the others 0.1 .. 0.6. Read as a distance, every query's smallest value is a wrong
// place: no answer is right, AUC 0. Reversed (max - S), every smallest value is the query's own
// place: every answer right, AUC 1.
cv::Mat1f AlignedSimilarity() {
  cv::Mat1f s(6, 6);
  for (int q = 0; q < 6; ++q)
    for (int c = 0; c < 6; ++c)
      s(q, c) = q == c ? 0.9f : 0.1f * static_cast<float>(1 + (q + c) % 6);
  return s;
}

GroundTruth AlignedTruth(int n) {
  GroundTruth t;
  t.references = n;
  for (int q = 0; q < n; ++q) t.matches.push_back({q});
  return t;
}

TEST(EvaluationWarnings, ASimilarityGivenAsDistancesLooksReversed) {
  EvaluationOptions o;
  o.tolerance = 0;
  const cv::Mat1f s = AlignedSimilarity();
  const EvaluationLayout layout = EvaluationLayout::QueryReference(6, 6);
  const GroundTruth truth = AlignedTruth(6);
  const PerQueryResult as_given = EvaluatePerQuery(s, layout, truth, o);
  EXPECT_EQ(as_given.auc, 0.0);
  // The reversed evaluation, computed independently: 1 - S ranks as max - S does.
  const cv::Mat1f distances = 1.0f - s;
  const double expected = EvaluatePerQuery(distances, layout, truth, o).auc;
  EXPECT_EQ(expected, 1.0);
  EXPECT_DOUBLE_EQ(ReversedAuc(s, layout, truth, o), expected);
  const std::vector<std::string> w = EvaluationWarnings(s, layout, truth, o, as_given);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("looks reversed: per-query AUC 0.000"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("1.000 with the largest"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("similarity"), std::string::npos) << w[0];
  EXPECT_EQ(w[0].find('\n'), std::string::npos);
  // The distances themselves: nothing to warn about.
  EXPECT_TRUE(
      EvaluationWarnings(distances, layout, truth, o, EvaluatePerQuery(distances, layout, truth, o))
          .empty());
}

TEST(EvaluationWarnings, APoorMatrixIsNotCalledReversed) {
  // Random distances rank badly either way: a low AUC alone is no reason to warn.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  cv::Mat1f m(200, 200);
  for (int q = 0; q < m.rows; ++q)
    for (int c = 0; c < m.cols; ++c) m(q, c) = u(rng);
  EvaluationOptions o;
  const EvaluationLayout layout = EvaluationLayout::QueryReference(200, 200);
  const GroundTruth truth = AlignedTruth(200);
  const PerQueryResult r = EvaluatePerQuery(m, layout, truth, o);
  ASSERT_LT(r.auc, kReversedAucBelow);
  EXPECT_LT(ReversedAuc(m, layout, truth, o), kReversedAucAtLeast);
  EXPECT_TRUE(EvaluationWarnings(m, layout, truth, o, r).empty());
}

TEST(EvaluationWarnings, NoTruePlaceNoValueNoQuery) {
  EvaluationOptions o;
  const cv::Mat1f s = 1.0f - AlignedSimilarity();
  const EvaluationLayout layout = EvaluationLayout::QueryReference(6, 6);
  // No query with a true place: the figures are 0 whatever the matrix.
  GroundTruth none = AlignedTruth(6);
  for (auto& m : none.matches) m.clear();
  std::vector<std::string> w =
      EvaluationWarnings(s, layout, none, o, EvaluatePerQuery(s, layout, none, o));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("no query has a true place among its candidates (6 queries; 0 pairs"),
            std::string::npos)
      << w[0];
  // Every candidate without a value.
  const cv::Mat1f empty(6, 6, std::numeric_limits<float>::infinity());
  w = EvaluationWarnings(empty, layout, AlignedTruth(6), o,
                         EvaluatePerQuery(empty, layout, AlignedTruth(6), o));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("no query has a candidate with a value"), std::string::npos) << w[0];
  // One sequence of 6 frames with candidates 100 frames back: no query at all.
  GroundTruth loop;
  loop.references = 6;
  loop.matches = {{}, {}, {}, {}, {}, {0}};
  const EvaluationLayout one = EvaluationLayout::LoopClosure(6);
  w = EvaluationWarnings(s, one, loop, o, EvaluatePerQuery(s, one, loop, o));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("no query has a candidate: 6 frames of one sequence"), std::string::npos)
      << w[0];
}

TEST(AnyCandidateHasValue, OnlyCandidateCellsCount) {
  const float inf = std::numeric_limits<float>::infinity();
  cv::Mat1f m(5, 5, inf);
  // One sequence, exclusion 3: the candidates are (3, 0), (4, 0) and (4, 1).
  m(4, 2) = 0.5f;  // within the exclusion window: not a candidate
  EXPECT_FALSE(AnyCandidateHasValue(m, EvaluationLayout::LoopClosure(5), 3));
  m(4, 1) = 0.5f;
  EXPECT_TRUE(AnyCandidateHasValue(m, EvaluationLayout::LoopClosure(5), 3));
  // Two traversals of 2 and 3 frames: only the lower-left 3 x 2 block holds candidates.
  cv::Mat1f t(5, 5, inf);
  t(0, 0) = t(4, 4) = 0.1f;
  EXPECT_FALSE(AnyCandidateHasValue(t, EvaluationLayout::TwoTraversals(2, 3), 100));
  t(3, 1) = 0.1f;
  EXPECT_TRUE(AnyCandidateHasValue(t, EvaluationLayout::TwoTraversals(2, 3), 100));
}

}  // namespace
}  // namespace openable
