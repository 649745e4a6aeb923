// Distances between panoramas described as n sub-panoramas (ABLE-P, Arroyo et al., IV 2014):
// the row of a frame is its n strip descriptors concatenated (Eq. 1). kAligned compares strip k
// with strip k (Eq. 2); kCrossCorrelation takes the best single pair of strips, whatever the
// heading (Eq. 3, 4, Algorithm 1); kCircular, beyond the paper, the best circular shift of the
// whole panorama, so no single uniform strip can tie two places. Every variant is symmetric with
// a zero diagonal; the last two cost n^2 single-strip matrices. docs/matching.md, "Panoramas".
#pragma once

#include <opencv2/core.hpp>
#include <optional>

#include "OpenABLE/base/enum_names.h"
#include "matching/distances.h"

namespace openable {

enum class PanoramaMatching { kAligned = 0, kCrossCorrelation = 1, kCircular = 2 };
OPENABLE_ENUM_NAMES(PanoramaMatching, "aligned", "cross-correlation", "circular")

// The N x N distance matrix of the rows of `rows` (N x (n * w): CV_8U compared with Hamming,
// CV_32F with L2, unless `metric` says otherwise), each row made of `strips` = n descriptors of
// w elements. `threads` as in
// distances.h (0 = all cores); `progress` counts single-strip matrices (cells). Throws
// std::invalid_argument when strips < 1 or the row width is not a multiple of strips.
cv::Mat1f PanoramaDistances(const cv::Mat& rows, int strips, PanoramaMatching mode, int threads = 0,
                            const PairProgress& progress = {},
                            std::optional<Metric> metric = std::nullopt);

// The rows of `rows` (N of them) against those of `references` (M, same width and type; empty:
// `rows` itself, as above): an N x M matrix whose cells equal those of the single-set matrix
// for the same pairs. A run spread over processes computes its share of rows with it.
cv::Mat1f PanoramaDistances(const cv::Mat& rows, const cv::Mat& references, int strips,
                            PanoramaMatching mode, int threads = 0,
                            const PairProgress& progress = {},
                            std::optional<Metric> metric = std::nullopt);

}  // namespace openable
