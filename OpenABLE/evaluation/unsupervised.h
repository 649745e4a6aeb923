// Criteria computed from a distance matrix alone, with no ground truth: how distinct the best
// matches are, how consistent the best matches of independent queries are, and the combined
// criterion that openable_sweep's --rank-by and the auto mode (Auto 1) rank settings by
// (docs/evaluation.md, "Without ground truth", gives the formulas and the measurements that
// chose them).
//
// Over the queries of the evaluated block (EvaluationLayout: the query-reference block of two
// traversals, or one sequence whose candidates lie Exclusion frames back), each query q with
// candidates has an answer b(q), its best candidate (matching/score.h), and the ratio r(q) of
// its distance to its best rival more than Match_score_window frames away:
//
//   distinctiveness = (1 / Q) sum_q (1 - r(q))     (a query without an answer adds 0)
//   consistency     = (1 / Q) sum_q a(q)           (a(q) = 1 when b(q) agrees with its
//                                                  independent partner's, matching/agreement.h)
//   agreement       = (10 consistency + distinctiveness) / 11
//
// Q counts the queries with candidates. Distinctiveness alone is fooled by a matrix whose best
// matches all fall on a few columns (each can be far below the rest of its row); consistency
// is not (answers stuck on one place never advance with the queries). Consistency decides and
// distinctiveness breaks its near-ties: many settings confirm every answer on easy data.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/evaluation/layout.h"
#include "matching/agreement.h"

namespace openable {

enum class UnsupervisedCriterion { kDistinctiveness, kConsistency, kAgreement };
OPENABLE_ENUM_NAMES(UnsupervisedCriterion, "distinctiveness", "consistency", "agreement")

struct UnsupervisedOptions {
  AgreementOptions agreement;  // L, Sequence_partial and Sequence_direction of the matrix
  int exclusion = 100;         // one sequence: candidates at least this many frames back
  int score_window = 10;       // the ratio's window (Match_score_window), >= 0
};

struct UnsupervisedFigures {
  int queries = 0;   // queries with candidates (Q)
  int answered = 0;  // of those, queries with a finite best candidate
  int agreeing = 0;  // of those, answers confirmed by their partner
  double distinctiveness = 0, consistency = 0, agreement = 0;
  int gap = 0, tolerance = 0;  // the partners' distance and tolerance, frames
  // Per query row of the block: its answer (block column, -1 none), ratio (1 without an
  // answer) and whether its answer agrees.
  std::vector<int> best;
  std::vector<float> ratio;
  std::vector<std::uint8_t> agrees;

  double Value(UnsupervisedCriterion c) const {
    switch (c) {
      case UnsupervisedCriterion::kDistinctiveness:
        return distinctiveness;
      case UnsupervisedCriterion::kConsistency:
        return consistency;
      case UnsupervisedCriterion::kAgreement:
        break;
    }
    return agreement;
  }
};

// The criteria of the block of `layout` in `matrix` (any scale: a normalised matrix, or sums
// before Eq. 5, give the same figures). Cells that are not finite are never answers nor
// rivals. Precondition (std::logic_error): the layout fits the matrix.
UnsupervisedFigures UnsupervisedCriteria(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                                         const UnsupervisedOptions& options);

}  // namespace openable
