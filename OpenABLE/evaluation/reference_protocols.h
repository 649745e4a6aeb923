// The metrics of the two evaluation codes most place-recognition papers report, computed as
// those codes compute them, so that a matrix's figures can be put next to published tables:
// VPR-Bench (Zaffar et al., IJCV 2021; its performance_comparison.py) and VPR_Tutorial
// (Schubert, Neubert et al., IEEE RAM 2023; its evaluation/metrics.py). docs/evaluation.md,
// "Protocols of VPR-Bench and VPR_Tutorial", gives the formulas side by side with the toolbox's
// own protocols and the differences.
//
// Both take a similarity S where the toolbox has a distance: S = -D, the negated normalised
// distance, exactly (no rounding). Cells without a value (+inf) take the block's largest
// finite distance, the least similar. Both need a query-reference layout (two traversals).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/protocols.h"

namespace openable {

// VPR-Bench: each query's best match (the most similar reference, the first of equals) is
// right when it is in the query's list of true references. A query without a true reference
// still counts: its best match is wrong, and it divides R@N.
struct VprBenchResult {
  int queries = 0;
  int queries_with_truth = 0;
  int right_best_matches = 0;  // the "matches" of performance_comparison.py
  // scikit-learn's precision_recall_curve over (matches, best-match similarities), as the
  // scikit-learn of VPR-Bench's environment (Python 2.7, at most 0.20) returns it: from the
  // lowest threshold that reaches full recall to the highest, then the point (recall 0,
  // precision 1). Recall is NaN throughout when no best match is right (tps[-1] = 0).
  std::vector<double> precision, recall;
  double auc_pr = 0;  // sklearn.metrics.auc(recall, precision): trapezoids
  // Extended precision (Ferrarini et al. 2020): (P_R0 + R_P100) / 2, P_R0 = precision[-2]
  // (the precision at the highest threshold), R_P100 = the recall of the first point with
  // precision 1, or 0 when P_R0 < 1.
  double extended_precision = 0;
  double recall_at_100p = 0;  // R_P100 above
  // RecallRate@N for N = 1 .. min(19, references): a true reference among the N most similar
  // (ties at the N-th similarity: lower reference index first), over all queries.
  std::vector<double> recall_at_n;
};

// VPR_Tutorial: the database is the reference traversal, the queries the other. GThard is
// the ground truth widened by the tolerance; GTsoft cells outside it (GroundTruth::soft) are
// neither right nor wrong: createPR sets their similarity to min(S) before thresholding.
struct VprTutorialResult {
  static constexpr int kThresholds = 100;  // createPR's n_thresh
  bool soft = false;                       // a GTsoft was given
  int queries_with_truth = 0;
  // createPR, matching "multi": every cell with S >= t is a match, for 100 thresholds t from
  // max(S) to min(S) (numpy.linspace), after the point (recall 0, precision 1).
  std::vector<double> precision_multi, recall_multi;
  double auc_multi = 0;             // numpy.trapz(P, R)
  double recall_at_100p_multi = 0;  // recallAt100precision: max R where P == 1
  // createPR, matching "single": each query's best match is accepted when S >= t. Not
  // computed with a GTsoft (createPR refuses the pair; `single` false).
  bool single = false;
  std::vector<double> precision_single, recall_single;
  double auc_single = 0, recall_at_100p_single = 0;
  // recallAtK for K = 1, 5, 10 (the demo's): a true reference among the K most similar
  // (ties: lower reference index first), over the queries with a true reference; NaN for a K
  // above the number of references (the reference code fails there).
  std::vector<int> k = {1, 5, 10};
  std::vector<double> recall_at_k;
};

// `normalized` is the full matrix; the block of `layout` (query-reference) is evaluated.
// `tolerance`: a reference within this many frames of a true one is true (0: the ground
// truth as given). Throws InputError when the layout is one sequence.
VprBenchResult EvaluateVprBench(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                const GroundTruth& truth, int tolerance);
VprTutorialResult EvaluateVprTutorial(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                      const GroundTruth& truth, int tolerance);

// Their entries of the table of protocols (protocols.h): the figures above as every report
// reads them.
ProtocolFigures VprBenchFigures(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                const GroundTruth& truth, int tolerance);
ProtocolFigures VprTutorialFigures(const cv::Mat1f& normalized, const EvaluationLayout& layout,
                                   const GroundTruth& truth, int tolerance);

}  // namespace openable
