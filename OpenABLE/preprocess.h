// Preprocessing of a frame before description.
#pragma once

#include <opencv2/core.hpp>

namespace openable {

// Grey 8-bit version of a frame as given by a FrameSource (CV_32FC1 or CV_32FC3 BGR in
// [0, 1]): OpenCV's luma weights (0.299 R + 0.587 G + 0.114 B), rounded to [0, 255].
// Throws std::logic_error on any other type.
cv::Mat1b ToGray8(const cv::Mat& frame);

}  // namespace openable
