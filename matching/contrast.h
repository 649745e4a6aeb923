// Local contrast enhancement of a single-frame distance matrix, as SeqSLAM does it (Milford and
// Wyeth, ICRA 2012, Sec. III-B), so that a query that looks alike to everything (a dark tunnel,
// fog) no longer wins every sequence:
//   D'(i, j) = (D(i, j) - mean_k D(i, k)) / std_k D(i, k),   k in [j - R, j + R]
// over the columns of the traversal of j (windows clipped at its ends; population standard
// deviation; D' = 0 where the window is constant), then shifted so the smallest value is 0, as
// the sequence sums and Eq. 5 expect (a constant shift changes no row's best cell).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace openable {

// SeqSLAM's local contrast enhancement of the single-frame matrix (Contrast_enhancement,
// Contrast_window): the one struct of these settings, held by the run's MatchingOptions and the
// online detector's OnlineOptions.
struct ContrastOptions {
  bool enabled = false;
  int window = 10;  // +-window references around each cell, 1..100000

  // Throws InputError naming Contrast_window when the window is out of range.
  void Check() const;
};

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
