// Monocular visual odometry: features matched between consecutive frames, the
// essential matrix with RANSAC (Nister's five-point solver, cv::findEssentialMat) and its
// decomposition into a rotation and a translation DIRECTION (cv::recoverPose, cheirality check).
//
// A single camera cannot know the scale: two views fix the translation only up to a factor
// (scaling the scene and the motion together gives the same images). The length of each step
// therefore comes from outside: Step's `step_length` (from a speedometer, or, for evaluation,
// the ground truth's step lengths); without it every step has unit length.
//
// Not from the SNAPS paper, which uses a stereo camera (stereo_odometry.h); this is the
// front-end for monocular sequences such as ../shared/datasets/kitti00_first1700 (left frames).
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "OpenABLE/odometry/calibration.h"
#include "OpenABLE/odometry/features.h"
#include "OpenABLE/odometry/step_stats.h"

namespace openable::odometry {

// The features (FeatureOptions: features, max_features, ratio_test) and the two-view
// geometry of each step.
struct MonoOdometryOptions : FeatureOptions {
  // RANSAC inlier threshold of the essential matrix (distance to the epipolar line), pixels,
  // > 0. 0.5 suits SIFT's sub-pixel keypoints: on KITTI 00 frames 0-1699 it gives 0.10 degree
  // of rotation error per step against 0.14 with 1.0, and an unaligned ATE of 9.6 m against
  // 12.6 m (docs/odometry.md); raise it to 1-2 for ORB or noisy images.
  double ransac_threshold_px = 0.5;
  // RANSAC confidence, in (0, 1).
  double ransac_confidence = 0.999;
  // Fewest RANSAC inliers (after the cheirality check) to accept a step, >= 5. Below it the
  // step keeps the previous motion (constant velocity) and StepStats says so.
  int min_inliers = 20;
  // Metres, >= 0: a given step_length below this is taken as standing still (identity motion,
  // StepStats::note "standing still"): a stopped camera gives no parallax, so the essential
  // matrix is undefined and RANSAC would fit noise. 0.02 m is 0.2 m/s at KITTI's 10 Hz.
  double still_step_length = 0.02;
  // Throws InputError naming the Config.txt key and the field ("Odometry_max_features
  // (MonoOdometryOptions.max_features)"; the field alone when no key sets it), the value and
  // the range. Defined in options.cc.
  void Check() const;
};

class MonoOdometry {
 public:
  // `intrinsics` of the (undistorted) frames; throws InputError on bad intrinsics or options.
  MonoOdometry(const Intrinsics& intrinsics, const MonoOdometryOptions& options);

  // Next grey frame (CV_8UC1, the size of the first). `step_length` = metres travelled since
  // the previous frame (ignored on the first frame); < 0 = unknown: unit length per step.
  // Returns the camera-to-world pose of this frame (OpenCV camera: x right, y down, z forward;
  // the first frame is the identity). A step with too few inliers repeats the previous
  // relative motion, its translation rescaled to `step_length` (StepStats::ok = false); a
  // step_length in [0, still_step_length) gives no motion.
  Eigen::Isometry3d Step(const cv::Mat& gray, double step_length);

  // Statistics of the last Step.
  const StepStats& last() const { return last_; }
  // Frames processed so far.
  int frames() const { return frames_; }

 private:
  Intrinsics intrinsics_;
  MonoOdometryOptions options_;
  FeatureExtractor extractor_;
  Features previous_;
  Eigen::Isometry3d pose_ = Eigen::Isometry3d::Identity();
  // Last accepted relative motion, previous-from-current, translation of unit length (or 0).
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
  StepStats last_;
  int frames_ = 0;
  cv::Size size_;
};

// Rotation angle of `r`, radians, in [0, pi].
double RotationAngle(const Eigen::Matrix3d& r);

}  // namespace openable::odometry
