// Figures of an evaluation: precision-recall curves (several runs in one figure) and the ground
// truth drawn over the distance matrix. Drawn with OpenCV (lines, Hershey text), no plotting
// library.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/metrics.h"

namespace openable {

// One run's curves, with its legend label ("LDB L=10").
struct PrSeries {
  std::string label;
  std::vector<CurvePoint> per_query;  // PerQueryResult::curve
  std::vector<CurvePoint> able_p;     // AblePResult::curve (may be empty)
};

// A white figure, two panels side by side: "Per-query best match" (precision against recall of
// each series' per_query curve) and "ABLE-P cells (vicinity V)" (the able_p curves of the
// series that have one; the panel is left out when every able_p is empty). Axes from 0 to 1
// labelled "Recall" and "Precision" with ticks every 0.1 and a light grid, one distinct colour per
// series, a legend with the labels and each series' AUC / AP, and `title` above. About 1400 x 640
// pixels with two panels.
cv::Mat3b RenderPrPlot(const std::vector<PrSeries>& series, const std::string& title, int vicinity);

// The evaluated block of `matrix` (normalised) in grey (dark = small distance), with the ground
// truth tinted blue, and each query's best match marked where it is accepted (at the operating
// point: `result.accepted`, which Match_consistency may make stricter than the threshold;
// without one, where its score is <= accept_threshold): green when correct, red when wrong.
// Queries are rows, references columns. Small blocks are enlarged by an integer factor
// (nearest neighbour) to at least 600 pixels on the longer side; marks are at least 3 x 3
// output pixels. A legend strip below the image names the colours. With `rejected` (geometric
// verification: cells (x = reference column, y = query row) of candidates that verification
// rejected), those are marked in magenta under the answers, and the answers are labelled
// "verified".
//
// Frame numbers (indices within the block: a traversal's frames from 0) are written along
// the top (references) and the left (queries) every 1, 2 or 5 x 10^n frames: the block
// starts kOverlayAxisLeft pixels from the left and kOverlayAxisTop from the top.
inline constexpr int kOverlayAxisLeft = 48;
inline constexpr int kOverlayAxisTop = 40;
cv::Mat3b RenderOverlay(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                        const GroundTruth& truth, const PerQueryResult& result,
                        double accept_threshold, const std::vector<cv::Point>* rejected = nullptr);

// The same figure without ground truth: the block in grey, no tint, and each query's answer
// best[q] (a column of the block, -1 none) marked orange where accepted[q] is 1, not judged
// right or wrong; the legend says so. `rejected` as above.
cv::Mat3b RenderAnswersOverlay(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                               const std::vector<int>& best,
                               const std::vector<std::uint8_t>& accepted,
                               const std::vector<cv::Point>* rejected = nullptr);

}  // namespace openable
