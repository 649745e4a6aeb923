#include "OpenABLE/preprocess.h"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace openable {

cv::Mat1b ToGray8(const cv::Mat& frame) {
  if (frame.depth() != CV_32F || frame.channels() > 3)
    throw std::logic_error("ToGray8: expected a CV_32FC1, CV_32FC2 or CV_32FC3 frame");
  cv::Mat gray;
  if (frame.channels() == 3)
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  else if (frame.channels() == 2)
    cv::extractChannel(frame, gray, 0);
  else
    gray = frame;
  cv::Mat1b out;
  gray.convertTo(out, CV_8U, 255.0);  // saturating and rounding
  return out;
}

cv::Mat ToGrayDisparity8(const cv::Mat& frame) {
  if (frame.type() != CV_32FC2)
    throw std::logic_error("ToGrayDisparity8: expected a CV_32FC2 stereo frame (grey, disparity)");
  cv::Mat out;
  frame.convertTo(out, CV_8U, 255.0);  // saturating and rounding, per channel
  return out;
}

}  // namespace openable
