// Large float matrices (the N x N distance matrix and its sequence sums) allocated in
// transparent huge pages where the kernel offers them (madvise(MADV_HUGEPAGE)): a 3576 x 3576
// matrix is 51 MB, and touching it page by page (4 KiB) cost about as much as computing it.
#pragma once

#include <opencv2/core.hpp>

namespace openable {

// An uninitialised rows x cols CV_32F matrix; at or above 8 MB it is backed by memory
// aligned to 2 MB and marked for huge pages. Otherwise a plain cv::Mat1f.
cv::Mat1f LargeMatrix(int rows, int cols);

}  // namespace openable
