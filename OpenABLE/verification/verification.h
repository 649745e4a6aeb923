// Geometric verification and temporal consistency of loop candidates: a candidate pair of
// frames is accepted only when local features (ORB or SIFT, Lowe's ratio test) agree with one
// rigid scene seen from two poses (fundamental or essential matrix by RANSAC, with a homography
// for the degenerate views of a still robot or a pure rotation), and optionally when the queries
// before it also found verified loops nearby. This is the check DLoopDetector (Galvez-Lopez and
// Tardos) and LFM-LCD (../shared/papers/004) put after the global descriptor: no learned model,
// and a wrong place rarely shows dozens of features consistent with one epipolar geometry.
// Steps: docs/verification.md, "What happens, per query".
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable {

enum class LocalFeatures { kOrb, kSift };
OPENABLE_ENUM_NAMES(LocalFeatures, "ORB", "SIFT")

// The Verification_* keys.
struct VerificationOptions {
  bool enabled = false;                          // Verification
  LocalFeatures features = LocalFeatures::kOrb;  // Verification_features
  int max_features = 500;                        // Verification_max_features, 10..100000
  double ratio = 0.8;                            // Verification_ratio, [0.1, 1]
  int min_inliers = 40;                          // Verification_min_inliers, 5..100000
  double ransac_threshold = 2.0;                 // Verification_ransac_threshold, pixels
  int candidates = 5;                            // Verification_candidates: k, 1..100
  int consistency = 1;                           // Verification_consistency: n, >= 0
  std::string calibration;                       // Verification_calibration; empty: none
  double calibration_scale = 1.0;                // Verification_calibration_scale
  double cache_mb = 1024;                        // Verification_cache: MB of features kept
  // Not a key: the frames within which references count as neighbours for the consistency
  // (the run takes Tolerance).
  int tolerance = 2;

  // Throws InputError naming the key of a value out of range.
  void Check() const;
};

// Pinhole intrinsics of the frames as they are read (pixels).
struct CameraIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

// The intrinsics of Verification_calibration: a KITTI calib.txt (P0 is taken) or an OpenABLE
// stereo calibration, OpenCV YAML (ML is taken), multiplied by `scale`. Throws InputError
// naming `key` and the file when it cannot be read as either.
CameraIntrinsics ReadVerificationCalibration(const std::string& path, double scale,
                                             const std::string& key);

// Throws InputError naming `key` when the intrinsics do not fit frames of `size` (the
// principal point outside the middle half of the image, the rule of CheckCalibrationFits).
void CheckIntrinsicsFit(const CameraIntrinsics& camera, const std::string& path,
                        const cv::Size& size, const std::string& first_image,
                        const std::string& key);

// The features of one frame, as verification keeps them: keypoint positions and descriptor
// rows (CV_8U for ORB, CV_32F for SIFT).
struct FrameFeatures {
  std::vector<cv::Point2f> points;
  cv::Mat descriptors;
  std::size_t Bytes() const {
    return points.size() * sizeof(cv::Point2f) + descriptors.total() * descriptors.elemSize();
  }
};

enum class GeometricModel { kNone, kFundamental, kEssential, kHomography };
OPENABLE_ENUM_NAMES(GeometricModel, "none", "fundamental", "essential", "homography")

struct PairCheck {
  int matches = 0;  // matches passing the ratio test
  int inliers = 0;  // inliers of `model` (0 with kNone)
  GeometricModel model = GeometricModel::kNone;
  bool verified = false;  // inliers >= min_inliers
};

class PairVerifier {
 public:
  // Throws InputError for options out of range (VerificationOptions::Check).
  PairVerifier(const VerificationOptions& options, std::optional<CameraIntrinsics> camera);
  // Features of an image: CV_8UC1/CV_8UC3 (BGR) or CV_32FC1/CV_32FC3 in [0, 1]. Thread-safe.
  FrameFeatures Extract(const cv::Mat& image) const;
  // The check of a query frame against a reference frame. Deterministic (OpenCV's RANSAC
  // draws from a fixed seed) and thread-safe.
  PairCheck Verify(const FrameFeatures& query, const FrameFeatures& reference) const;
  const VerificationOptions& Options() const { return options_; }
  bool Calibrated() const { return camera_.has_value(); }
  // The descriptor rows Extract gives: elements per row and OpenCV type (ORB: 32 CV_8U, SIFT:
  // 128 CV_32F). Features kept elsewhere (a saved map) must have them to be verified.
  int DescriptorWidth() const { return descriptor_width_; }
  int DescriptorType() const { return descriptor_type_; }

 private:
  VerificationOptions options_;
  std::optional<CameraIntrinsics> camera_;
  int norm_;
  int descriptor_width_ = 0, descriptor_type_ = 0;
};

// One candidate of a query and what verification found.
struct VerifiedCandidate {
  int reference = -1;  // frame of the reference traversal
  int rank = 0;        // 1 = the best distinct place of the query, 2, ...
  float distance = 0;  // normalised distance M'
  float score = 0;     // Match_score of the candidate
  PairCheck check;
  int streak = 0;         // consecutive queries with a verified loop near this one (this included)
  bool accepted = false;  // check.verified and streak > consistency
};

struct QueryVerification {
  int query = -1;                             // frame of the query traversal
  std::vector<VerifiedCandidate> candidates;  // rank order
  // Index in `candidates` of the query's answer: the best-ranked accepted candidate; -1: none.
  int answer = -1;
};

// Sets the streaks, `accepted` and `answer` of `current` from `previous` (the query before it,
// or nullptr). A verified candidate's streak is 1 plus the longest streak of the previous
// query's verified candidates whose reference lies within `tolerance` frames of its own (0 when
// the previous query is not the previous frame); it is accepted when its streak exceeds
// `consistency`, as DLoopDetector's islands require.
void ContinueStreaks(const QueryVerification* previous, QueryVerification& current, int consistency,
                     int tolerance);

// The same over queries in frame order.
void ApplyTemporalConsistency(std::vector<QueryVerification>& queries, int consistency,
                              int tolerance);

}  // namespace openable
