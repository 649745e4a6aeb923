#include "OpenABLE/odometry/features.h"

#include <algorithm>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable::odometry {

FeatureExtractor::FeatureExtractor(const std::string& name, int max_features,
                                   const std::string& key) {
  const std::string upper = Upper(name);
  if (upper == "ORB") {
    detector_ = cv::ORB::create(max_features);
    norm_ = cv::NORM_HAMMING;
  } else if (upper == "SIFT") {
    detector_ = cv::SIFT::create(max_features);
    norm_ = cv::NORM_L2;
  } else {
    throw InputError(key + ": unknown feature type " + Quoted(name) + ", expected ORB or SIFT");
  }
}

Features FeatureExtractor::Extract(const cv::Mat& gray) const {
  Features f;
  detector_->detectAndCompute(gray, cv::noArray(), f.keypoints, f.descriptors);
  return f;
}

std::vector<cv::DMatch> MatchWithRatioTest(const Features& from, const Features& to, int norm,
                                           double ratio) {
  std::vector<cv::DMatch> kept;
  if (from.descriptors.empty() || to.descriptors.rows < 2) return kept;
  cv::BFMatcher matcher(norm, false);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(from.descriptors, to.descriptors, knn, 2);
  kept.reserve(knn.size());
  for (const auto& m : knn) {
    if (m.size() == 2 && m[0].distance < ratio * m[1].distance) kept.push_back(m[0]);
  }
  return kept;
}

}  // namespace openable::odometry
