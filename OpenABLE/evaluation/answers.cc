#include "OpenABLE/evaluation/answers.h"

#include <algorithm>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <stdexcept>
#include <string>

#include "OpenABLE/base/error.h"
#include "matching/agreement.h"
#include "matching/score.h"

namespace openable {
namespace {

// Every query without an answer yet, nothing accepted.
QueryAnswers NoAnswers(int queries) {
  QueryAnswers a;
  const auto n = static_cast<std::size_t>(std::max(queries, 0));
  a.best.assign(n, -1);
  a.distance.assign(n, std::numeric_limits<float>::infinity());
  a.score.assign(n, std::numeric_limits<float>::infinity());
  return a;
}

}  // namespace

int QueryAnswers::Accepted() const {
  return static_cast<int>(std::count(accepted.begin(), accepted.end(), 1));
}

int QueryAnswers::Confirmed() const {
  return static_cast<int>(std::count(confirmed.begin(), confirmed.end(), 1));
}

void AcceptAnswers(const std::vector<int>& best, const std::vector<float>& score,
                   const EvaluationOptions& options, std::vector<std::uint8_t>& accepted,
                   std::vector<std::uint8_t>& confirmed) {
  if (score.size() != best.size())
    throw std::logic_error("AcceptAnswers: one score per answer expected");
  accepted.assign(best.size(), 0);
  confirmed.assign(best.size(), 0);
  if (options.accept_threshold < 0 || options.accept_none) return;
  std::vector<std::uint8_t> agree;
  if (options.accept_consistency > 0) {
    AgreementOptions a = options.agreement;
    a.partners = options.accept_consistency;
    agree = AgreeingAnswers(best, a);
  }
  for (std::size_t q = 0; q < best.size(); ++q) {
    if (best[q] < 0 || !(score[q] <= options.accept_threshold)) continue;
    accepted[q] = 1;
    confirmed[q] = agree.empty() || agree[q] ? 1 : 0;
  }
}

QueryAnswers AnswersOfMatrix(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                             const EvaluationOptions& options) {
  if (layout.queries < 0 || layout.references < 0 || layout.row_offset < 0 ||
      layout.col_offset < 0 || layout.row_offset + layout.queries > matrix.rows ||
      layout.col_offset + layout.references > matrix.cols)
    throw std::logic_error("AnswersOfMatrix: the layout does not fit a " +
                           std::to_string(matrix.rows) + " x " + std::to_string(matrix.cols) +
                           " matrix");
  options.score.CheckRivals(layout.references, "");
  const int nq = layout.queries;
  QueryAnswers a = NoAnswers(nq);
  std::vector<std::uint8_t> has_candidates(static_cast<std::size_t>(nq), 0);
  cv::parallel_for_(cv::Range(0, nq), [&](const cv::Range& range) {
    for (int q = range.start; q < range.end; ++q) {
      const int end = layout.CandidateEnd(q, options.exclusion);
      if (end == 0) continue;
      has_candidates[q] = 1;
      const float* row = matrix.ptr<float>(layout.row_offset + q) + layout.col_offset;
      const int best = BestCandidate(row, end);
      if (best < 0) continue;
      a.best[q] = best;
      a.distance[q] = row[best];
      a.score[q] = ScoreOfCandidate(row, end, best, options.score);
    }
  });
  for (int q = 0; q < nq; ++q) {
    a.queries += has_candidates[q];
    a.answered += a.best[q] >= 0 ? 1 : 0;
  }
  AcceptAnswers(a.best, a.score, options, a.accepted, a.confirmed);
  return a;
}

QueryAnswers AnswersOfCandidates(const EvaluationLayout& layout,
                                 const std::vector<std::vector<Answer>>& answers,
                                 const EvaluationOptions& options) {
  const int nq = layout.queries;
  if (static_cast<int>(answers.size()) != nq)
    throw std::logic_error("AnswersOfCandidates: one answer list per query expected");
  QueryAnswers a = NoAnswers(nq);
  for (int q = 0; q < nq; ++q) {
    if (layout.CandidateEnd(q, options.exclusion) == 0) continue;
    ++a.queries;
    if (answers[q].empty()) continue;
    const Answer& first = answers[q].front();
    a.best[q] = first.column;
    a.distance[q] = first.distance;
    a.score[q] = first.score;
    ++a.answered;
  }
  AcceptAnswers(a.best, a.score, options, a.accepted, a.confirmed);
  return a;
}

}  // namespace openable
