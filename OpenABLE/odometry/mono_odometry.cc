#include "OpenABLE/odometry/mono_odometry.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/odometry/features.h"

namespace openable::odometry {

double RotationAngle(const Eigen::Matrix3d& r) { return Eigen::AngleAxisd(r).angle(); }

MonoOdometry::MonoOdometry(const Intrinsics& intrinsics, const MonoOdometryOptions& options)
    : intrinsics_(intrinsics),
      options_((options.Check(), options)),
      extractor_(options.features, options.max_features, "MonoOdometryOptions.features") {
  intrinsics_.Check("MonoOdometry");
}

Eigen::Isometry3d MonoOdometry::Step(const cv::Mat& gray, double step_length) {
  const auto start = std::chrono::steady_clock::now();
  if (gray.type() != CV_8UC1 || gray.empty())
    throw std::logic_error("MonoOdometry::Step: expected a non-empty CV_8UC1 image");
  if (frames_ > 0 && gray.size() != size_)
    throw std::logic_error("MonoOdometry::Step: frame size changed");
  size_ = gray.size();
  last_ = StepStats();
  Features current = extractor_.Extract(gray);
  last_.features = static_cast<int>(current.keypoints.size());

  if (frames_ == 0) {
    last_.note = "first frame";
  } else if (step_length >= 0 && step_length < options_.still_step_length) {
    last_.note = "standing still";  // pose unchanged; the velocity is kept for later
  } else {
    const std::vector<cv::DMatch> matches =
        MatchWithRatioTest(previous_, current, extractor_.Norm(), options_.ratio_test);
    last_.matches = static_cast<int>(matches.size());
    bool estimated = false;
    Eigen::Isometry3d previous_from_current = Eigen::Isometry3d::Identity();
    if (last_.matches >= std::max(options_.min_inliers, 5)) {
      std::vector<cv::Point2d> p_prev, p_curr;
      p_prev.reserve(matches.size());
      p_curr.reserve(matches.size());
      for (const cv::DMatch& m : matches) {
        p_prev.emplace_back(previous_.keypoints[m.queryIdx].pt);
        p_curr.emplace_back(current.keypoints[m.trainIdx].pt);
      }
      const cv::Mat K(intrinsics_.K());
      cv::theRNG().state = 0x12345678;  // deterministic RANSAC
      cv::Mat mask;
      const cv::Mat E =
          cv::findEssentialMat(p_prev, p_curr, K, cv::RANSAC, options_.ransac_confidence,
                               options_.ransac_threshold_px, mask);
      if (E.rows == 3 && E.cols == 3) {
        cv::Mat R, t;
        // recoverPose: x_curr = R x_prev + t, |t| = 1; mask keeps the points in front of
        // both cameras. Its default distance threshold (50 baselines) would drop the far
        // points of short steps (at 0.17 m, everything beyond 8.5 m), hence 1e4.
        cv::Mat triangulated;
        const int good = cv::recoverPose(E, p_prev, p_curr, K, R, t, 1e4, mask, triangulated);
        last_.inliers = good;
        if (good >= options_.min_inliers) {
          Eigen::Matrix3d r;
          Eigen::Vector3d tt;
          cv::cv2eigen(R, r);
          cv::cv2eigen(t, tt);
          previous_from_current.linear() = r.transpose();
          previous_from_current.translation() = -r.transpose() * tt;
          estimated = true;
        }
      }
    }
    if (estimated) {
      velocity_ = previous_from_current;
      const double n = velocity_.translation().norm();
      if (n > 0) velocity_.translation() /= n;
    } else {
      last_.ok = false;
      std::ostringstream s;
      s << "too few inliers (" << last_.inliers << " of " << last_.matches << " matches, "
        << "need " << options_.min_inliers << "): constant velocity";
      last_.note = s.str();
    }
    Eigen::Isometry3d motion = velocity_;
    motion.translation() *= step_length < 0 ? 1.0 : step_length;
    pose_ = pose_ * motion;
  }
  previous_ = std::move(current);
  ++frames_;
  last_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return pose_;
}

}  // namespace openable::odometry
