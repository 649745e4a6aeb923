// Rectification of stereo pairs: both images are warped so that a scene point appears on the
// same row in the left and the right image (epipolar lines horizontal).
#pragma once

#include <opencv2/core.hpp>

#include "OpenABLE/stereo/calibration.h"

namespace openable {

class StereoRectifier {
 public:
  // Computes the rectifying transforms and remap tables once, for images of `image_size`
  // (cv::stereoRectify with CALIB_ZERO_DISPARITY, then cv::initUndistortRectifyMap for each
  // camera). `alpha` is stereoRectify's free scaling: 0 (the default here) zooms so that
  // every rectified pixel is valid (no black borders, which a global descriptor would
  // otherwise see as structure), -1 lets OpenCV choose, 1 keeps every source pixel. The
  // rectified images have `image_size` too.
  StereoRectifier(const StereoCalibration& calibration, const cv::Size& image_size,
                  double alpha = 0.0);

  // Rectifies a pair of CV_8UC1 images of image_size (bilinear remap); an empty `right`
  // rectifies the left image only (right_rectified is then empty). Thread-safe.
  void Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_rectified,
               cv::Mat& right_rectified) const;

  cv::Size ImageSize() const { return size_; }
  // Focal length of the rectified images, pixels (P1(0,0)).
  double Focal() const { return projection_left_(0, 0); }
  // Baseline, in the unit of T: |P2(0,3) / P2(0,0)|.
  double Baseline() const;
  // stereoRectify's outputs: rectifying rotations, new projection matrices, disparity-to-depth
  // matrix Q.
  const cv::Matx33d& RectifyingRotationLeft() const { return rotation_left_; }
  const cv::Matx33d& RectifyingRotationRight() const { return rotation_right_; }
  const cv::Matx34d& ProjectionLeft() const { return projection_left_; }
  const cv::Matx34d& ProjectionRight() const { return projection_right_; }
  const cv::Matx44d& DisparityToDepth() const { return q_; }

 private:
  cv::Size size_;
  cv::Matx33d rotation_left_, rotation_right_;
  cv::Matx34d projection_left_, projection_right_;
  cv::Matx44d q_;
  cv::Mat map_left_x_, map_left_y_, map_right_x_, map_right_y_;  // CV_16SC2 + CV_16UC1
};

}  // namespace openable
