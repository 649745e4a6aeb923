// Distances between panoramas described as n sub-panoramas (ABLE-P, Arroyo et al., IV 2014).
//
// A panoramic frame is cut into n equal-width vertical strips (sub-panoramas) and each strip is
// described on its own; the row of a frame is the n strip descriptors concatenated (Eq. 1 of
// ABLE-P). Three ways to compare two such rows v_i, v_j (strip k of v_i is v_{i,k}):
//
//  - kAligned (Eq. 2): the plain distance of the concatenated rows, strip k against strip k.
//    Hamming: sum over k of bits(v_{i,k} XOR v_{j,k}). L2: the Euclidean norm of the whole row.
//    A place seen again in the same direction is found; one seen in the opposite direction
//    (the panorama turned by half a revolution) is not.
//  - kCrossCorrelation (Eq. 3, 4, Algorithm 1): C_{k,l} = d(v_{i,k}, v_{j,l}) for every pair of
//    strips, and M(i, j) = min over k, l of C_{k,l}: the best single pair of strips. Finds a place
//    whatever the heading, as the paper proposes.
//  - kCircular (chosen here, beyond the paper): the panorama turned by s strips, the best s:
//    M(i, j) = min over s of D_s with D_s the aligned distance of v_i against v_j with its
//    strips circularly shifted by s (Hamming: sum over k of d(v_{i,k}, v_{j,(k+s) mod n});
//    L2: sqrt of the sum of squared strip distances). It keeps the whole panorama in the
//    comparison, as the aligned distance does, and is exactly the aligned distance at s = 0.
//    A revisit in the opposite direction is a shift of n/2 strips when n is even.
//
// Every variant is symmetric with a zero diagonal. Costs n^2 (cross-correlation and circular)
// single-strip distance matrices; the aligned variant costs one.
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
