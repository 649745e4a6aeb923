// Keypoints and their matching between consecutive frames, shared by both odometries.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <string>
#include <vector>

namespace openable::odometry {

// The features both odometries match between frames, with the same defaults.
struct FeatureOptions {
  // "ORB" or "SIFT" (case-insensitive). SIFT by default: its keypoints are located to a
  // fraction of a pixel, ORB's to the pixel of their pyramid level; on KITTI 00 frames 0-199
  // (half size) SIFT gives 0.11 degree of rotation error per step against ORB's 0.24-0.5, and
  // is faster there (fewer keypoints found on the small frames). See docs/odometry.md.
  std::string features = "SIFT";
  // Keypoints kept per frame (strongest), >= 10. 2000 leaves several hundred inliers on KITTI.
  int max_features = 2000;
  // Lowe's ratio test, in [0.1, 1]: a match is kept when its distance is below ratio x the
  // second nearest's. 0.8 is Lowe's value.
  double ratio_test = 0.8;
};

// Keypoints of one frame and their descriptors (one row each).
struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

// Detector + descriptor by name: "ORB" (binary, Hamming distance; FAST corners with the
// Harris score, 8 pyramid levels, scale 1.2 as OpenCV's defaults) or "SIFT" (float, L2; the
// paper's choice, Lowe's defaults). Case-insensitive. `max_features` caps the keypoints kept
// (strongest first). Throws InputError naming `key` and listing the valid names otherwise.
class FeatureExtractor {
 public:
  FeatureExtractor(const std::string& name, int max_features, const std::string& key);
  // Keypoints and descriptors of a CV_8UC1 image.
  Features Extract(const cv::Mat& gray) const;
  // The descriptor distance: cv::NORM_HAMMING (ORB) or cv::NORM_L2 (SIFT).
  int Norm() const { return norm_; }
  // The descriptor rows Extract gives: elements per row and OpenCV type (ORB: 32 CV_8U, SIFT:
  // 128 CV_32F).
  int DescriptorWidth() const { return detector_->descriptorSize(); }
  int DescriptorType() const { return detector_->descriptorType(); }

 private:
  cv::Ptr<cv::Feature2D> detector_;
  int norm_ = cv::NORM_L2;
};

// Matches `from` to `to` by brute force (2 nearest neighbours in `to` per descriptor of
// `from`) and keeps a match when its distance is below `ratio` x the second's (Lowe's ratio
// test). queryIdx indexes `from`, trainIdx `to`. Deterministic. Empty when either is empty.
std::vector<cv::DMatch> MatchWithRatioTest(const Features& from, const Features& to, int norm,
                                           double ratio);

}  // namespace openable::odometry
