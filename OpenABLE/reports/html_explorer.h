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
#include <string>

#include <opencv2/core.hpp>

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

// The section: its HTML, the embedded data and the script.
std::string ExplorerSection(const ReportInput& input);

}  // namespace openable
