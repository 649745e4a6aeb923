#include "OpenABLE/stereo/disparity.h"

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <stdexcept>
#include <string>

namespace openable {

DisparityOptions DisparityOptions::ForWidth(int width) {
  DisparityOptions o;
  if (width < 512) o.num_disparities = std::max(16, width / 4 / 16 * 16);
  if (width < 320) o.block_size = 3;
  return o;
}

void DisparityOptions::Check() const {
  if (num_disparities < 16 || num_disparities > 256 || num_disparities % 16 != 0)
    throw std::logic_error("DisparityOptions: num_disparities " + std::to_string(num_disparities) +
                           " is not a multiple of 16 in [16, 256]");
  if (block_size < 1 || block_size > 11 || block_size % 2 == 0)
    throw std::logic_error("DisparityOptions: block_size " + std::to_string(block_size) +
                           " is not odd in [1, 11]");
  if (p1 < 0 || p2 < 0 || (p1 > 0 && p2 > 0 && p2 <= p1))
    throw std::logic_error("DisparityOptions: expected 0 <= P1 < P2");
}

cv::Mat1f ComputeDisparity(const cv::Mat& left, const cv::Mat& right, const DisparityOptions& o) {
  o.Check();
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size())
    throw std::logic_error("ComputeDisparity: expected two CV_8UC1 images of one size");
  const int area = o.block_size * o.block_size;
  const int p1 = o.p1 > 0 ? o.p1 : 8 * area;
  const int p2 = o.p2 > 0 ? o.p2 : 32 * area;
  const cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      0, o.num_disparities, o.block_size, p1, p2, o.disp12_max_diff, 63, o.uniqueness_ratio,
      o.speckle_window_size, o.speckle_range, cv::StereoSGBM::MODE_SGBM);
  cv::Mat raw;  // CV_16S, disparity x 16, invalid = (minDisparity - 1) x 16 = -16
  sgbm->compute(left, right, raw);
  cv::Mat1f out;
  raw.convertTo(out, CV_32F, 1.0 / 16.0);
  out.setTo(0.0f, out < 0.0f);
  return out;
}

cv::Mat1f NormalizeDisparity(const cv::Mat1f& disparity, const DisparityOptions& o) {
  cv::Mat1f out;
  disparity.convertTo(out, CV_32F, 1.0 / o.num_disparities);
  return out;
}

}  // namespace openable
