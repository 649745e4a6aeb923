// The answers of a distance matrix without ground truth: per query of the evaluated block its
// best match, that match's distance and score, and what the run's operating point does with it
// (Match_threshold accepts it, Match_consistency confirms it). They are what the per-query
// protocol judges when there is ground truth (metrics.h, which accepts its answers by the same
// rule, AcceptAnswers); a page or a file that shows a run without ground truth shows these
// (the HTML report without Ground_truth_type, OpenABLE/reports/html_report.h).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/metrics.h"

namespace openable {

struct QueryAnswers {
  // Per query row of the block: its best candidate column (-1 without an answer: no candidate
  // with a value), the normalised distance of that cell and its score (Match_score: the
  // distance, or the ratio to the best rival); +inf without an answer.
  std::vector<int> best;
  std::vector<float> distance;
  std::vector<float> score;
  // Per query: 1 when its answer's score is <= Match_threshold (none when Match_threshold is
  // -1, or when the auto mode trusted no setting).
  std::vector<std::uint8_t> accepted;
  // Per query: 1 when it is accepted and, with Match_consistency n, the answers of n
  // independent queries agree with it (matching/agreement.h); without Match_consistency every
  // accepted answer is confirmed. The confirmed answers are the run's matches: what the run
  // report counts as accepted, and the evaluation's operating point with ground truth.
  std::vector<std::uint8_t> confirmed;
  int queries = 0;   // queries with at least one candidate
  int answered = 0;  // of those, queries with an answer

  int Accepted() const;   // answers accepted
  int Confirmed() const;  // answers confirmed
};

// The acceptance rule of an operating point over per-query answers `best` (-1: none) and their
// `score`s: fills `accepted` and `confirmed` as QueryAnswers describes them, from
// options.accept_threshold (-1: nothing accepted), options.accept_consistency (with
// options.agreement) and options.accept_none. The per-query protocol's operating point is the
// confirmed answers (PerQueryResult::accepted).
void AcceptAnswers(const std::vector<int>& best, const std::vector<float>& score,
                   const EvaluationOptions& options, std::vector<std::uint8_t>& accepted,
                   std::vector<std::uint8_t>& confirmed);

// The answers of the block `layout` of `matrix` (normalised, M'): each query's best candidate
// (the smallest finite distance among its candidates, the lowest column on ties; with one
// sequence the frames at least options.exclusion back), scored by options.score and
// options.score.window, accepted and confirmed by AcceptAnswers. The best matches and scores
// are those EvaluatePerQuery finds. Throws std::logic_error when the layout does not fit the
// matrix, InputError when a ratio's window leaves no rival (Match_score_window).
QueryAnswers AnswersOfMatrix(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                             const EvaluationOptions& options);

// The answers chosen elsewhere (geometric verification: answers[q] lists query q's accepted
// candidates, best first; empty: no answer), accepted and confirmed by AcceptAnswers as
// EvaluateAnswers does. `queries` counts the queries with candidates (loop closure: those at
// least options.exclusion frames from the start).
QueryAnswers AnswersOfCandidates(const EvaluationLayout& layout,
                                 const std::vector<std::vector<Answer>>& answers,
                                 const EvaluationOptions& options);

}  // namespace openable
