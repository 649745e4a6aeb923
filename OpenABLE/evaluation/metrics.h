// The two evaluation protocols of docs/evaluation.md over the evaluated block of a distance
// matrix: per-query best match (AUC, R@100P, max F1, R@N) and the ABLE papers' cell protocol
// (100 thresholds, temporal vicinity, average precision).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/protocols.h"
#include "matching/agreement.h"
#include "matching/score.h"

namespace openable {

struct EvaluationOptions {
  int tolerance = 2;          // frames: an answer within this many frames of a true match is right
  int exclusion = 100;        // loop closure: candidates are frames at least this far back
  int vicinity = 7;           // ABLE-P protocol: temporal vicinity, frames
  int able_thresholds = 100;  // ABLE-P protocol: thresholds evenly spaced in [0, 1]
  // Per-query protocol: what ranks and accepts a query's best match (matching/score.h): its
  // distance, or the ratio to the best rival outside +-window frames.
  MatchScoreOptions score;
  // Per-query protocol: the operating point a user chose (Match_threshold): answers with a
  // score <= accept_threshold are accepted; -1: none.
  double accept_threshold = -1.0;
  // Match_consistency n: an answer is accepted only when n partners agree with it
  // (matching/agreement.h, with the L, Sequence_partial and Sequence_direction of `agreement`);
  // 0: the score alone decides.
  int accept_consistency = 0;
  AgreementOptions agreement;
  // The auto mode found no setting it could trust (Auto_min_consistency): nothing is accepted.
  bool accept_none = false;
  // The protocols reported (Evaluation_protocol): the toolbox's own are always computed (its
  // files and figures need them); VPR-Bench's and VPR_Tutorial's when chosen.
  EvaluationProtocols protocols;

  // Throws InputError naming the key of a value out of range (Tolerance, Exclusion, Vicinity,
  // Match_score_window, Match_threshold, Match_consistency, Image_sequences; able_thresholds).
  void Check() const;
};

// One point of a precision-recall curve.
struct CurvePoint {
  double threshold = 0;  // accept distances <= threshold (per query) / cells < threshold (ABLE-P)
  double precision = 0;
  double recall = 0;
  double f1 = 0;
  std::int64_t tp = 0, fp = 0;
};

struct PerQueryResult {
  int queries = 0;           // queries with at least one candidate
  int positive_queries = 0;  // of those, queries with a true match among their candidates
  // Of the queries, those whose candidates are all non-finite (sequence cells skipped at the
  // start of a traversal): they give no answer, and a positive one lowers recall.
  int unanswered = 0;
  std::int64_t truth_pairs_outside_candidates = 0;  // true pairs no candidate set contains
  // One point per distinct score of a best match (EvaluationOptions::score: the distance or
  // the ratio), in increasing order of threshold: a query's answer is accepted when its score
  // is <= the threshold.
  std::vector<CurvePoint> curve;
  double auc = 0;             // sum of precision x recall increments along the curve
  double recall_at_100p = 0;  // highest recall with precision exactly 1 (0 if none)
  double max_f1 = 0;
  double max_f1_threshold = 0;
  double max_f1_precision = 0, max_f1_recall = 0;
  // At EvaluationOptions::accept_threshold (when >= 0): the answers accepted (score <= the
  // threshold, agreeing with their partners under accept_consistency, none under
  // accept_none), and their precision (1 when none is accepted) and recall; `accepted` marks
  // them per query row.
  bool has_operating_point = false;
  CurvePoint operating_point;
  std::vector<std::uint8_t> accepted;
  // R@N for N = 1, 5, 10: share of positive queries with a correct match among the N best
  // candidates (ties broken by lower column index).
  double recall_at_1 = 0, recall_at_5 = 0, recall_at_10 = 0;
  // Per query row of the block: best candidate column (-1 without a finite candidate), its
  // distance and its score, whether the query is positive and whether its best candidate is
  // correct.
  std::vector<int> best;
  std::vector<float> best_distance;
  std::vector<float> score;
  std::vector<std::uint8_t> positive, correct;
};

struct AblePResult {
  // One point per threshold theta_k = k / (able_thresholds - 1), k = 0 .. able_thresholds - 1;
  // precision is 1 by convention where nothing is detected (recall is then 0).
  std::vector<CurvePoint> curve;
  double average_precision = 0;  // area under the curve in percent (step-wise, as AUC)
  std::int64_t candidate_cells = 0;
  std::int64_t truth_cells = 0;  // ground-truth pairs among the candidate cells
};

// Step-wise area under a curve: the sum over its points, in order, of
// precision x (recall - previous recall), previous recall starting at 0. PerQueryResult::auc,
// and AblePResult::average_precision / 100.
double CurveArea(const std::vector<CurvePoint>& curve);

// `matrix` is the full matrix (normalised, M'); the block of `layout` is evaluated.
// Precondition (std::logic_error): the layout fits the matrix and the ground truth the layout.
PerQueryResult EvaluatePerQuery(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                                const GroundTruth& truth, const EvaluationOptions& options);
// One accepted answer of a query (geometric verification): a candidate column of the block,
// its normalised distance and its score.
struct Answer {
  int column = -1;
  float distance = 0;
  float score = 0;
};

// The per-query protocol over answers chosen elsewhere: answers[q] lists query q's accepted
// candidates, best first (empty: no answer, a miss when q is positive). The query's answer is
// the first; R@N counts the first N. Queries, positives and the curve are as EvaluatePerQuery's
// (the curve sweeps the answers' scores); `unanswered` counts the candidate queries without
// an answer.
PerQueryResult EvaluateAnswers(const EvaluationLayout& layout, const GroundTruth& truth,
                               const std::vector<std::vector<Answer>>& answers,
                               const EvaluationOptions& options);
AblePResult EvaluateAbleP(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                          const GroundTruth& truth, const EvaluationOptions& options);

// Whether a candidate cell of the block of `layout` (the earlier frames at least `exclusion`
// back for one sequence) holds a value (is finite).
bool AnyCandidateHasValue(const cv::Mat1f& matrix, const EvaluationLayout& layout, int exclusion);

// An evaluation whose ranking looks reversed: the per-query AUC of `matrix` is below
// kReversedAucBelow while the same evaluation of the matrix reversed (each finite cell d of the
// block replaced by max - d, max the block's largest finite cell; cells without a value stay
// without) reaches at least kReversedAucAtLeast, two and a half times as much or more. A
// similarity (large = same place) read as a distance ranks so: each query's "best match" is
// its least similar place, which is almost never right, while the most similar often is. A
// poor distance matrix ranks badly both ways (random distances: about the share of right
// answers by chance either way), so a low AUC alone is no reason to warn.
inline constexpr double kReversedAucBelow = 0.1;
inline constexpr double kReversedAucAtLeast = 0.25;

// The per-query AUC of the matrix reversed as above, with the settings of `options` (its
// operating point and confirmation left out: they do not change the AUC).
double ReversedAuc(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                   const GroundTruth& truth, const EvaluationOptions& options);

// What makes the figures of an evaluation say little about the matrix, one line each (none
// when nothing does), for Test_OpenABLE, openable_evaluate and Python's evaluate alike: no
// query has a candidate (one sequence shorter than the exclusion), no query has a true place
// among its candidates (the figures are 0 whatever the matrix), no query has a candidate with a
// value (every candidate cell +inf), and a ranking that looks reversed (above). `result` is
// EvaluatePerQuery's on the same matrix, layout, truth and options.
std::vector<std::string> EvaluationWarnings(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                                            const GroundTruth& truth,
                                            const EvaluationOptions& options,
                                            const PerQueryResult& result);

}  // namespace openable
