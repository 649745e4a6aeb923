// Disparity of a rectified stereo pair by semi-global block matching (OpenCV's StereoSGBM),
// as ABLE-S computes it (0-128 disparities), and its normalisation to [0, 1].
#pragma once

#include <opencv2/core.hpp>

namespace openable {

struct DisparityOptions {
  // Disparities searched, pixels: [0, num_disparities). A multiple of 16 (SGBM's rule),
  // 16-256. 128 as the original; ForWidth lowers it for narrow images.
  int num_disparities = 128;
  // Side of the matched block, pixels, odd, 1-11.
  int block_size = 5;
  // SGBM smoothness penalties for a disparity change of 1 (P1) and of more than 1 (P2) between
  // neighbours; 0 = OpenCV's usual 8 x block_size^2 and 32 x block_size^2. P2 > P1.
  int p1 = 0;
  int p2 = 0;
  // A match is kept when its cost beats the second best by this percentage (5-15 usual).
  int uniqueness_ratio = 10;
  // Connected blobs of fewer pixels than this whose disparities vary by more than
  // speckle_range are invalidated (0 disables the filter).
  int speckle_window_size = 100;
  int speckle_range = 2;
  // Maximum difference, pixels, of the left-right consistency check (-1 disables).
  int disp12_max_diff = 1;

  // Options for images `width` pixels wide: num_disparities = 128 when width >= 512, else the
  // largest multiple of 16 not above width / 4 (at least 16), so that the searched range
  // stays a quarter of the width (disparities scale with the image); block_size 5, or 3 below
  // 320 pixels.
  static DisparityOptions ForWidth(int width);
  // Throws std::logic_error on values outside the ranges above.
  void Check() const;
};

// Disparity of the rectified CV_8UC1 pair, in pixels (CV_32FC1, 1/16 pixel steps). Pixels
// without a valid match (SGBM's invalid value, the left band where the search would leave the
// right image, speckles) are 0. Thread-safe (a matcher per call).
cv::Mat1f ComputeDisparity(const cv::Mat& left, const cv::Mat& right,
                           const DisparityOptions& options);

// disparity / num_disparities, in [0, 1): with 128 disparities, the original's d / 128; times
// 255 it is the 8-bit disparity image that D-LDB describes. Invalid (0) stays 0.
cv::Mat1f NormalizeDisparity(const cv::Mat1f& disparity, const DisparityOptions& options);

}  // namespace openable
