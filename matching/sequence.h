// Sequence matching (ABLE; SeqSLAM's idea of comparing sequences of frames instead of single
// frames): the distance between the place of frame i and the place of frame j is the sum of
// the L single-frame distances along the diagonal that ends at (i, j):
//
//   S(i, j) = sum_{k = 0 .. L-1} D(i - k, j - k)
//
// L = 1 gives single images back, as the paper says (the original summed L + 1 terms).
//
// Traversals: the frames of a run may be several traversals concatenated (a query route after
// a reference route). A sum never crosses from one traversal into another: the terms that
// would start before the first frame of the traversal of i, or of j, do not exist.
//
// Early frames: where only c < L terms exist (the first L - 1 frames of a traversal), the sum
// of the c terms is scaled by L / c, i.e. the mean distance along the available part of the
// diagonal times L. Leaving the short sums unscaled would make early frames look similar to
// everything.
//
// The cost is one pass over the matrix whatever L is: a running sum per diagonal.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace openable {

// D: N x M single-frame distances (rows: frames i, columns: frames j). `row_starts` and
// `col_starts` are the first frame of each traversal along the rows and the columns, in
// increasing order and starting with 0 (empty means {0}: one traversal). Returns S as above.
// Throws std::logic_error when L < 1 or the starts are not increasing from 0.
cv::Mat1f SequenceDistances(const cv::Mat1f& d, int sequence_length,
                            const std::vector<int>& row_starts = {},
                            const std::vector<int>& col_starts = {});

}  // namespace openable
