// Local contrast enhancement of a single-frame distance matrix, as SeqSLAM does it (Milford and
// Wyeth, "SeqSLAM: Visual Route-Based Navigation for Sunny Summer Days and Stormy Winter
// Nights", ICRA 2012, Sec. III-B): a query's distances to the references are put on a common
// footing with its distances to the nearby references, so that a query that looks alike to
// everything (a dark tunnel, fog) no longer wins every sequence.
//
//   D'(i, j) = (D(i, j) - mean_k D(i, k)) / std_k D(i, k),   k in [j - R, j + R]
//
// over the columns k of the traversal of j (a window is clipped at its traversal's ends), the
// standard deviation being the population one; D' = 0 where the window's values are all
// equal. The matrix is then shifted so that its smallest value is 0 (the sequence sums and
// Eq. 5 expect distances >= 0; a constant shift does not change which cell of a row is best).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace openable {

// Enhances `d` (rows: frames i, columns: frames j) in place with window `window` >= 1;
// `col_starts` as in matching/sequence.h (the first column of each traversal, from 0; empty:
// one traversal). Non-finite cells are left out of every mean and deviation and stay as they
// are. `threads` = 0 uses all cores. Throws std::logic_error on a window below 1.
void EnhanceContrast(cv::Mat1f& d, int window, const std::vector<int>& col_starts = {},
                     int threads = 0);

// The same without the final shift: each cell is its z-score within its window, and the
// smallest of them is returned (+inf when no cell is finite). For searches that enhance a few
// rows at a time and shift them by a value fixed beforehand (a map's tuned settings, online.h).
// A z-score among the 2R + 1 values of a window is at least -sqrt(2R) (Samuelson's
// inequality), so a shift of sqrt(2 window) never leaves a cell below 0.
float EnhanceContrastUnshifted(cv::Mat1f& d, int window, const std::vector<int>& col_starts = {},
                               int threads = 0);

}  // namespace openable
