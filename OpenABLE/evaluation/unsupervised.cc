#include "OpenABLE/evaluation/unsupervised.h"

#include <stdexcept>

#include "OpenABLE/base/option_checks.h"
#include "matching/score.h"

namespace openable {

void UnsupervisedOptions::Check() const {
  CheckIntAtLeast("Image_sequences", agreement.sequence_length, 1);
  CheckIntAtLeast("Exclusion", exclusion, 1);
  score.Check();
}

UnsupervisedFigures UnsupervisedCriteria(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                                         const UnsupervisedOptions& options) {
  if (layout.row_offset < 0 || layout.col_offset < 0 || layout.queries < 0 ||
      layout.references < 0 || layout.row_offset + layout.queries > matrix.rows ||
      layout.col_offset + layout.references > matrix.cols)
    throw std::logic_error("UnsupervisedCriteria: the layout does not fit the matrix");
  UnsupervisedFigures out;
  const int nq = layout.queries;
  out.best.assign(nq, -1);
  out.ratio.assign(nq, 1.0f);
  double margin = 0;
  for (int q = 0; q < nq; ++q) {
    const int end = layout.CandidateEnd(q, options.exclusion);
    if (end == 0) continue;
    ++out.queries;
    const float* row = matrix.ptr<float>(layout.row_offset + q) + layout.col_offset;
    const int best = BestCandidate(row, end);
    if (best < 0) continue;
    ++out.answered;
    out.best[q] = best;
    out.ratio[q] = ScoreOfCandidate(row, end, best, {MatchScore::kRatio, options.score.window});
    margin += 1.0 - out.ratio[q];
  }
  out.agrees = AgreeingAnswers(out.best, options.agreement);
  for (const std::uint8_t a : out.agrees) out.agreeing += a;
  out.gap = options.agreement.Gap();
  out.tolerance = options.agreement.Tolerance();
  if (out.queries > 0) {
    out.distinctiveness = margin / out.queries;
    out.consistency = static_cast<double>(out.agreeing) / out.queries;
    out.agreement = (10.0 * out.consistency + out.distinctiveness) / 11.0;
  }
  return out;
}

}  // namespace openable
