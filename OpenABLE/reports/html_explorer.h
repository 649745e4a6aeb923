// The interactive part of the HTML report (section "explore", docs/output_formats.md): for
// each run, the matrix to hover and click (the two frames of a cell, its distance and the
// query's score), a threshold slider that moves the operating point along the precision-recall
// curve and redraws the accepted best matches, and the queries listed by score with their
// frames. Plain JavaScript inside the page, nothing fetched; the data it works on is embedded
// compactly: per query its best match, score and distance exactly, the block quantised to 8
// bits, a matrix image at most kExploreImageSide pixels a side, and the frames of the block as
// JPEG thumbnail sheets.
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/reports/html_report.h"

namespace openable {

// The explorer's matrix image: pixels a side at most (larger blocks are downsampled).
inline constexpr int kExploreImageSide = 1000;
// The 8-bit values of the block: cells a side at most; a larger block is embedded as the mean
// of groups of cells (the page says so).
inline constexpr int kExploreValuesSide = 2048;
// Thumbnails of the frames: pixels high and across at most; all of a report's thumbnails
// together at most kThumbnailPixels pixels (smaller cells beyond).
inline constexpr int kExploreThumbHeight = 96;
inline constexpr int kExploreThumbWidth = 160;
inline constexpr double kExploreThumbnailPixels = 16e6;

// The 8-bit code of a normalised distance in the embedded block: round(254 d) for d in [0, 1]
// (clamped), 255 for a cell without a value (NaN, +inf).
std::uint8_t ExploreCode(float distance);

// The block of `layout` in `matrix` as the explorer embeds it: ExploreCode of each cell, or of
// the mean of the finite cells of each group of cell_rows x cell_cols cells when a side is
// longer than kExploreValuesSide (cell_rows, cell_cols set here; 1 x 1 otherwise).
cv::Mat1b ExploreValues(const cv::Mat1f& matrix, const EvaluationLayout& layout, int& cell_rows,
                        int& cell_cols);

// One run as every section of the page reads it, with ground truth (an evaluated run) or
// without (ReportAnswers): ReportRuns(input)[i] is the run of input.matrices[i].
struct ReportRun {
  std::string label, source;
  EvaluationLayout layout;
  const cv::Mat1f* matrix = nullptr;
  MatchScoreOptions score;  // Match_score and its window
  int exclusion = 100;
  // Per query: the answer, its distance and score, and at the operating point accepted
  // (score <= threshold) and confirmed (the run's matches; PerQueryResult::accepted with
  // ground truth).
  QueryAnswers answers;
  bool has_operating_point = false;  // Match_threshold is set (or verified answers)
  // The threshold the page starts from: the operating point's, else (with ground truth) the
  // max-F1 threshold; -1 without either.
  double threshold = -1;
  int consistency = 0;     // Match_consistency
  bool untrusted = false;  // the auto mode accepted nothing
  bool verified = false;
  const EvaluatedRun* evaluated = nullptr;  // with ground truth
  const GroundTruth* truth = nullptr;       // with ground truth
};

// The runs of the page. Throws std::logic_error when there is not one matrix per run, or a
// run's answers do not fit its layout or its matrix.
std::vector<ReportRun> ReportRuns(const ReportInput& input);

// The steps of ExplorerSection for progress: one per frame it reads (when input.frames can be
// read) and one per run (its matrix image).
std::int64_t ExplorerSteps(const ReportInput& input, const std::vector<ReportRun>& runs);

// The section: its HTML, the embedded data and the script; `step` is called after each of
// its ExplorerSteps.
std::string ExplorerSection(
    const ReportInput& input, const std::vector<ReportRun>& runs,
    const std::function<void()>& step = [] {});

}  // namespace openable
