#include "OpenABLE/odometry/stereo_odometry.h"

#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/ximgproc/disparity_filter.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/odometry/features.h"
#include "OpenABLE/stereo/disparity.h"

namespace openable::odometry {
namespace {

cv::Ptr<cv::StereoMatcher> LeftMatcher(const StereoOdometryOptions& o) {
  const DisparityOptions& d = o.disparity;
  if (Upper(o.matcher) == "BM") return cv::StereoBM::create(d.num_disparities, d.block_size);
  const int area = d.block_size * d.block_size;
  return cv::StereoSGBM::create(0, d.num_disparities, d.block_size, 8 * area, 32 * area,
                                d.disp12_max_diff, 63, d.uniqueness_ratio, d.speckle_window_size,
                                d.speckle_range, cv::StereoSGBM::MODE_SGBM);
}

}  // namespace

cv::Mat1f OdometryDisparity(const cv::Mat& left, const cv::Mat& right,
                            const StereoOdometryOptions& o) {
  o.Check();
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size() ||
      left.empty())
    throw std::logic_error("OdometryDisparity: expected two CV_8UC1 images of one size");
  const bool bm = Upper(o.matcher) == "BM";
  if (!bm && !o.wls_filter) return ComputeDisparity(left, right, o.disparity);

  const cv::Ptr<cv::StereoMatcher> left_matcher = LeftMatcher(o);
  cv::Mat left_raw, result;  // CV_16S, disparity x 16
  left_matcher->compute(left, right, left_raw);
  if (o.wls_filter) {
    const cv::Ptr<cv::ximgproc::DisparityWLSFilter> wls =
        cv::ximgproc::createDisparityWLSFilter(left_matcher);
    const cv::Ptr<cv::StereoMatcher> right_matcher = cv::ximgproc::createRightMatcher(left_matcher);
    cv::Mat right_raw;
    right_matcher->compute(right, left, right_raw);
    wls->setLambda(o.wls_lambda);
    wls->setSigmaColor(o.wls_sigma);
    wls->filter(left_raw, left, result, right_raw);
  } else {
    result = left_raw;
  }
  cv::Mat1f disparity;
  result.convertTo(disparity, CV_32F, 1.0 / 16.0);
  disparity.setTo(0.0f, disparity <= 0.0f);
  const int band = std::min(o.disparity.num_disparities, disparity.cols);
  disparity.colRange(0, band).setTo(0.0f);
  return disparity;
}

StereoOdometry::StereoOdometry(const Intrinsics& rectified_left, double baseline,
                               const StereoOdometryOptions& options)
    : intrinsics_(rectified_left),
      baseline_(baseline),
      options_((options.Check(), options)),
      extractor_(options.features, options.max_features, "StereoOdometryOptions.features") {
  intrinsics_.Check("StereoOdometry");
  if (!(baseline > 0) || !std::isfinite(baseline))
    throw InputError("StereoOdometry: baseline " + std::to_string(baseline) + " m, expected > 0");
}

Eigen::Isometry3d StereoOdometry::Step(const cv::Mat& left_gray, const cv::Mat& right_gray) {
  const auto start = std::chrono::steady_clock::now();
  last_ = StepStats();
  cv::Mat1f disparity = OdometryDisparity(left_gray, right_gray, options_);
  if (frames_ > 0 && disparity.size() != previous_disparity_.size())
    throw std::logic_error("StereoOdometry::Step: frame size changed");
  Features current = extractor_.Extract(left_gray);
  last_.features = static_cast<int>(current.keypoints.size());

  if (frames_ == 0) {
    last_.note = "first frame";
  } else {
    const std::vector<cv::DMatch> matches =
        MatchWithRatioTest(previous_, current, extractor_.Norm(), options_.ratio_test);
    // 3D points of the previous frame (Eq. 1, 2) and their 2D matches in the current one.
    std::vector<cv::Point3d> points;
    std::vector<cv::Point2d> pixels;
    const double f = intrinsics_.fx;
    for (const cv::DMatch& m : matches) {
      const cv::Point2f p = previous_.keypoints[m.queryIdx].pt;
      const int u = cvRound(p.x), v = cvRound(p.y);
      if (u < 0 || v < 0 || u >= previous_disparity_.cols || v >= previous_disparity_.rows)
        continue;
      const double d = previous_disparity_(v, u);
      if (d <= 0) continue;
      const double z = baseline_ * f / d;  // Eq. 1
      if (z > options_.max_depth) continue;
      points.emplace_back(z * (p.x - intrinsics_.cx) / intrinsics_.fx,  // Eq. 2
                          z * (p.y - intrinsics_.cy) / intrinsics_.fy, z);
      pixels.emplace_back(current.keypoints[m.trainIdx].pt);
    }
    last_.matches = static_cast<int>(points.size());
    bool estimated = false;
    if (last_.matches >= std::max(options_.min_inliers, 6)) {
      cv::Mat rvec, tvec;
      std::vector<int> inliers;
      cv::theRNG().state = 0x12345678;  // deterministic RANSAC
      const bool solved = cv::solvePnPRansac(
          points, pixels, cv::Mat(intrinsics_.K()), cv::noArray(), rvec, tvec, false,
          options_.pnp_iterations, static_cast<float>(options_.pnp_reprojection_px),
          options_.pnp_confidence, inliers, cv::SOLVEPNP_ITERATIVE);
      last_.inliers = static_cast<int>(inliers.size());
      if (solved && last_.inliers >= options_.min_inliers) {
        // Eq. 3 with p_w in the previous camera's frame: x_curr = R x_prev + t.
        cv::Mat R;
        cv::Rodrigues(rvec, R);
        Eigen::Matrix3d r;
        Eigen::Vector3d t;
        cv::cv2eigen(R, r);
        cv::cv2eigen(tvec, t);
        if (r.allFinite() && t.allFinite()) {
          velocity_.linear() = r.transpose();
          velocity_.translation() = -r.transpose() * t;
          estimated = true;
        }
      }
    }
    if (!estimated) {
      last_.ok = false;
      std::ostringstream s;
      s << "too few PnP inliers (" << last_.inliers << " of " << last_.matches
        << " matches with depth, need " << options_.min_inliers << "): constant velocity";
      last_.note = s.str();
    }
    pose_ = pose_ * velocity_;
  }
  previous_ = std::move(current);
  previous_disparity_ = disparity;
  ++frames_;
  last_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return pose_;
}

}  // namespace openable::odometry
