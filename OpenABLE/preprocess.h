// Preprocessing of a frame before description.
#pragma once

#include <opencv2/core.hpp>

namespace openable {

// Grey 8-bit version of a frame as given by a FrameSource (CV_32FC1 or CV_32FC3 BGR in
// [0, 1]): OpenCV's luma weights (0.299 R + 0.587 G + 0.114 B), rounded to [0, 255]. A stereo
// frame (CV_32FC2: rectified left grey, disparity; OpenABLE/stereo/stereo_source.h) gives its
// channel 0, so every descriptor describes the rectified left image.
// Throws std::logic_error on any other type.
cv::Mat1b ToGray8(const cv::Mat& frame);

// Both channels of a stereo frame (CV_32FC2 in [0, 1]) as CV_8UC2 (value x 255, rounded): the
// patch D-LDB describes. Throws std::logic_error on any other type.
cv::Mat ToGrayDisparity8(const cv::Mat& frame);

}  // namespace openable
