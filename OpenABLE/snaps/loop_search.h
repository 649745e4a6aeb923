// SNAPS's online loop-candidate search (Sec. III-B) and the online correction that goes with
// it (Sec. III-C): fed frame by frame, as a SLAM system would call it.
#pragma once

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "OpenABLE/snaps/discounted.h"
#include "OpenABLE/snaps/quality_index.h"
#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

// Every design parameter of Table I plus those of Sec. II-E / III-A. Values the paper gives
// are its values; the others are ours (the paper gives none) and documented in docs/snaps.md.
struct SearchOptions {
  // Sec. III-A: thumbnails at 1/6 of the frame (used by the callers that make thumbnails).
  double thumbnail_scale = kThumbnailScale;
  // B of the sliding window (Sec. II-E). The paper gives no value; 8 is Wang & Bovik's.
  int window = 8;
  // "Minimum similarity" (Table I), 75 % in Sec. III-B.
  double min_similarity = 0.75;
  // Yaw-difference limit between the current and the reference pose, 10 degrees (Sec. III-B).
  double max_yaw_difference_deg = 10.0;
  // "Radius" (Table I), metres around the current (corrected) position. Not given: 10 m.
  double radius = 10.0;
  // "Frame difference" M (Table I): candidates are frames j <= N - M. Not given: 100 frames
  // (10 s of KITTI at 10 Hz).
  int frame_distance = 100;
  // "Attempts" (Table I): at most this many candidates (nearest first) are compared. Not
  // given: 10.
  int attempts = 10;
  // false: the most similar of the examined candidates with Q >= min_similarity is accepted;
  // true: the first one (nearest first) with Q >= min_similarity, stopping there.
  bool accept_first = false;
  // "Inter-frame pause" and "discount factor length" K (Table I): see DiscountOptions.
  DiscountOptions discount;
  // Vertical axis of the world frame, for the yaw: KITTI's world is the first camera frame,
  // whose y axis points down; (0, 0, 1) for a z-up world (TUM). The heading of a pose is its
  // optical axis (camera z) projected on the plane normal to this axis.
  Eigen::Vector3d vertical = Eigen::Vector3d::UnitY();

  // Throws InputError naming the key (Snaps_window, Snaps_radius, ...) of a value out of range.
  // Defined in options.cc.
  void Check() const;
};

// Yaw difference in degrees, in [0, 180], between two camera-to-world poses (see
// SearchOptions::vertical). 0 when a heading is parallel to the vertical.
double YawDifferenceDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                        const Eigen::Vector3d& vertical);

// What one Step did.
struct StepRecord {
  double seconds = 0;   // wall time of the search (steady_clock)
  int candidates = 0;   // candidates compared (Q computed), <= attempts
  bool paused = false;  // within the inter-frame pause: no search
  bool loop = false;    // a loop was returned
};

class LoopSearch {
 public:
  explicit LoopSearch(const SearchOptions& options);

  // Frame `index` (must be the number of frames stepped so far: 0, 1, 2, ...) at `pose`
  // (camera-to-world, the corrected pose when the caller corrects online) with its thumbnail
  // (single channel, the same size for every frame). Stores the frame, then searches:
  // candidates are frames j <= index - M, within `radius` of the position, with a yaw
  // difference <= the limit, nearest first; at most `attempts` are compared by
  // UniversalQualityIndex; a loop {index, j, Q} is returned for the best (or first) with
  // Q >= min_similarity, and `index` becomes the last pinned frame. No search while
  // index - last pinned frame <= pause. Throws std::invalid_argument on a wrong index or a
  // thumbnail of another size or type than the first.
  std::optional<LoopPair> Step(int index, const Eigen::Isometry3d& pose, const cv::Mat& thumbnail);

  // Stored poses, one per frame stepped; a caller correcting online updates their positions.
  std::vector<Eigen::Isometry3d>& poses() { return poses_; }
  const std::vector<Eigen::Isometry3d>& poses() const { return poses_; }
  const std::vector<StepRecord>& records() const { return records_; }
  int last_pinned() const { return last_pinned_; }
  int loops_closed() const { return loops_closed_; }
  const SearchOptions& options() const { return options_; }

 private:
  SearchOptions options_;
  std::vector<Eigen::Isometry3d> poses_;
  std::vector<cv::Mat> thumbnails_;
  std::vector<StepRecord> records_;
  int last_pinned_ = -1;
  int loops_closed_ = 0;
};

// Online SNAPS: the odometry's poses come in one by one; each is shifted by the correction
// accumulated so far (frames after a loop are built by the odometry on top of the corrected
// frame N, and Eq. 6 does not rotate), searched for a loop with that corrected position, and
// a loop found corrects frames N-K..N at once (ApplyDiscountedUpdate, alpha = loops closed).
class OnlineSnaps {
 public:
  explicit OnlineSnaps(const SearchOptions& options) : search_(options) {}
  // The next frame's odometry pose (camera-to-world) and thumbnail. Returns the loop closed,
  // if any.
  std::optional<LoopPair> Step(const Eigen::Isometry3d& odometry_pose, const cv::Mat& thumbnail);
  const std::vector<Eigen::Isometry3d>& corrected() const { return search_.poses(); }
  const LoopSearch& search() const { return search_; }
  const std::vector<LoopPair>& loops() const { return loops_; }
  // Seconds spent in the correction of each closed loop (steady_clock).
  const std::vector<double>& correction_seconds() const { return correction_seconds_; }

 private:
  LoopSearch search_;
  Eigen::Vector3d offset_ = Eigen::Vector3d::Zero();
  std::vector<LoopPair> loops_;
  std::vector<double> correction_seconds_;
};

// Mean and spread of latencies (the paper's box plot, Fig. 5). Quartiles by linear
// interpolation between order statistics. All 0 (count 0) for no value.
struct LatencyStats {
  int count = 0;
  double mean = 0, min = 0, q1 = 0, median = 0, q3 = 0, max = 0;
};
LatencyStats Summarize(std::vector<double> seconds);

}  // namespace openable::snaps
