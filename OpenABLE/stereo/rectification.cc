#include "OpenABLE/stereo/rectification.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace openable {

StereoRectifier::StereoRectifier(const StereoCalibration& c, const cv::Size& image_size,
                                 double alpha)
    : size_(image_size) {
  const cv::Mat ml(c.left_camera), mr(c.right_camera);
  const cv::Mat dl(c.left_distortion), dr(c.right_distortion);
  const cv::Mat r(c.rotation), t(c.translation);
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(ml, dl, mr, dr, size_, r, t, r1, r2, p1, p2, q, cv::CALIB_ZERO_DISPARITY, alpha,
                    size_);
  rotation_left_ = cv::Matx33d(r1);
  rotation_right_ = cv::Matx33d(r2);
  projection_left_ = cv::Matx34d(p1);
  projection_right_ = cv::Matx34d(p2);
  q_ = cv::Matx44d(q);
  cv::initUndistortRectifyMap(ml, dl, r1, p1, size_, CV_16SC2, map_left_x_, map_left_y_);
  cv::initUndistortRectifyMap(mr, dr, r2, p2, size_, CV_16SC2, map_right_x_, map_right_y_);
}

double StereoRectifier::Baseline() const {
  return std::abs(projection_right_(0, 3) / projection_right_(0, 0));
}

void StereoRectifier::Rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_rectified,
                              cv::Mat& right_rectified) const {
  cv::remap(left, left_rectified, map_left_x_, map_left_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  if (right.empty()) {
    right_rectified.release();
    return;
  }
  cv::remap(right, right_rectified, map_right_x_, map_right_y_, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT);
}

}  // namespace openable
