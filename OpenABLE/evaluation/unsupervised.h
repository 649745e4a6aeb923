// Criteria computed from a distance matrix alone, with no ground truth: distinctiveness of the
// best matches, consistency of the best matches of independent queries (matching/agreement.h),
// and agreement = (10 consistency + distinctiveness) / 11, by which openable_sweep's --rank-by
// and the auto mode (Auto 1) rank settings. Consistency decides because distinctiveness alone is
// fooled by best matches stuck on a few columns; distinctiveness breaks its near-ties. Formulas
// and the measurements that chose them: docs/evaluation.md, "Without ground truth".
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/evaluation/layout.h"
#include "matching/agreement.h"
#include "matching/score.h"

namespace openable {

enum class UnsupervisedCriterion { kDistinctiveness, kConsistency, kAgreement };
OPENABLE_ENUM_NAMES(UnsupervisedCriterion, "distinctiveness", "consistency", "agreement")

struct UnsupervisedOptions {
  AgreementOptions agreement;  // L, Sequence_partial and Sequence_direction of the matrix
  int exclusion = 100;         // one sequence: candidates at least this many frames back
  // Its window: distinctiveness is the ratio score (its kind is not used).
  MatchScoreOptions score;

  // Throws InputError naming Image_sequences, Exclusion or Match_score_window.
  void Check() const;
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
