// Stereo visual odometry as in the SNAPS paper ("Similarity and Location-based Real-time Loop
// Closure: SNAPS for SLAM in Unexplored Environments"), Sec. II-B to II-D:
//   1. disparity of the rectified pair by block matching (OpenCV), then the disparity map filter
//      based on weighted least squares (cv::ximgproc::DisparityWLSFilter, Min et al.);
//   2. depth of the previous frame's keypoints from the disparity, Eq. 1: z = B f / d, and their
//      3D position in the previous camera's frame, Eq. 2: x = z (u - u0) / f, y = z (v - v0) / f;
//   3. SIFT keypoints matched between consecutive left frames (Lowe's ratio test);
//   4. the current camera's pose from those 3D-2D matches, Eq. 3 s p_c = K [R|T] p_w, solved by
//      PnP inside RANSAC (cv::solvePnPRansac, then Levenberg-Marquardt on the inliers).
// Changed / chosen here, not stated by the paper: semi-global block matching (StereoSGBM) by
// default, plain block matching (StereoBM, the paper's "block matching") selectable; ORB
// selectable instead of SIFT; points beyond max_depth dropped (their disparity is below a few
// pixels, so their depth is mostly noise); the left band where the disparity search leaves the
// right image gives no depth; a constant-velocity fallback when PnP fails.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>

#include "OpenABLE/odometry/calibration.h"
#include "OpenABLE/odometry/features.h"
#include "OpenABLE/odometry/step_stats.h"
#include "OpenABLE/stereo/disparity.h"

namespace openable::odometry {

// The features (FeatureOptions: features, max_features, ratio_test), the disparity and the PnP
// of each step.
struct StereoOdometryOptions : FeatureOptions {
  // Disparity: "sgbm" (semi-global, OpenCV's StereoSGBM with the penalties of
  // OpenABLE/stereo/disparity.h) or "bm" (StereoBM, block_size >= 5). Case-insensitive.
  std::string matcher = "sgbm";
  // Apply the WLS disparity filter (left and right disparity, ximgproc), as the paper.
  bool wls_filter = true;
  // WLS smoothness (lambda, > 0; 8000 is OpenCV's usual value) and edge sensitivity to the
  // image (sigma_color, > 0; 1.5 likewise).
  double wls_lambda = 8000, wls_sigma = 1.5;
  // The disparity search (OpenABLE/stereo/disparity.h; bm uses its range and block only):
  // num_disparities a multiple of 16 in [16, 256], 64 here, which suits 620-752 pixel wide
  // frames (KITTI half size: a point at 2.7 m; EuRoC: 0.8 m); block_size odd, 1-11 for sgbm,
  // 5-11 for bm.
  DisparityOptions disparity = [] {
    DisparityOptions d;
    d.num_disparities = 64;
    d.block_size = 5;
    return d;
  }();
  // Metres, >= 1: points farther than this (in the previous frame) are not used in PnP.
  double max_depth = 80;
  // RANSAC of PnP: inlier reprojection error, pixels (> 0); iterations (>= 1); confidence (0, 1).
  double pnp_reprojection_px = 2.0;
  int pnp_iterations = 200;
  double pnp_confidence = 0.999;
  // Fewest PnP inliers to accept a step, >= 4; below, constant velocity.
  int min_inliers = 15;
  // Throws InputError naming the Config.txt key and the field ("Odometry_max_depth
  // (StereoOdometryOptions.max_depth)"; the field alone when no key sets it), the value and
  // the range. Defined in options.cc.
  void Check() const;
};

// Disparity of a rectified CV_8UC1 pair as StereoOdometry computes it, pixels (CV_32FC1); 0
// where there is none (invalid, or the left band of num_disparities columns).
cv::Mat1f OdometryDisparity(const cv::Mat& left, const cv::Mat& right,
                            const StereoOdometryOptions& options);

class StereoOdometry {
 public:
  // `rectified_left`: intrinsics of the rectified left image (fx = fy = f of Eq. 1-2 for a
  // rectified pair); `baseline` in metres (> 0). Throws InputError on bad values or options.
  StereoOdometry(const Intrinsics& rectified_left, double baseline,
                 const StereoOdometryOptions& options);

  // Next rectified pair (CV_8UC1, one size). Returns the camera-to-world pose of the left
  // camera (OpenCV camera axes; the first frame is the identity), translation in metres.
  Eigen::Isometry3d Step(const cv::Mat& left_gray, const cv::Mat& right_gray);

  const StepStats& last() const { return last_; }
  int frames() const { return frames_; }

 private:
  Intrinsics intrinsics_;
  double baseline_;
  StereoOdometryOptions options_;
  FeatureExtractor extractor_;
  Features previous_;
  cv::Mat1f previous_disparity_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();  // previous-from-current
  StepStats last_;
  int frames_ = 0;
};

}  // namespace openable::odometry
