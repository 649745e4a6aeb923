#include "OpenABLE/snaps/loop_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace openable::snaps {

double YawDifferenceDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                        const Eigen::Vector3d& vertical) {
  const Eigen::Vector3d up = vertical.normalized();
  auto heading = [&](const Eigen::Isometry3d& p) {
    const Eigen::Vector3d z = p.linear().col(2);
    return Eigen::Vector3d(z - z.dot(up) * up);
  };
  const Eigen::Vector3d ha = heading(a), hb = heading(b);
  if (ha.norm() < 1e-12 || hb.norm() < 1e-12) return 0.0;
  const double angle = std::atan2(ha.cross(hb).dot(up), ha.dot(hb));
  return std::abs(angle) * 180.0 / M_PI;
}

LoopSearch::LoopSearch(const SearchOptions& options) : options_(options) {
  if (options.window < 1 || options.frame_distance < 1 || options.attempts < 0 ||
      options.radius < 0 || options.discount.pause < 0 || options.discount.discount_length < 0)
    throw std::invalid_argument(
        "LoopSearch: need window >= 1, frame distance >= 1, attempts, radius, pause, K >= 0");
}

std::optional<LoopPair> LoopSearch::Step(int index, const Eigen::Isometry3d& pose,
                                         const cv::Mat& thumbnail) {
  const auto start = std::chrono::steady_clock::now();
  if (index != static_cast<int>(poses_.size()))
    throw std::invalid_argument("LoopSearch::Step: index " + std::to_string(index) + ", expected " +
                                std::to_string(poses_.size()));
  if (thumbnail.empty() || thumbnail.channels() != 1 ||
      (!thumbnails_.empty() &&
       (thumbnail.size() != thumbnails_[0].size() || thumbnail.type() != thumbnails_[0].type())))
    throw std::invalid_argument("LoopSearch::Step: thumbnail of frame " + std::to_string(index) +
                                " empty, not one channel, or of another size or type");
  poses_.push_back(pose);
  thumbnails_.push_back(thumbnail);
  StepRecord record;
  std::optional<LoopPair> found;
  if (last_pinned_ >= 0 && index - last_pinned_ <= options_.discount.pause) {
    record.paused = true;
  } else {
    const Eigen::Vector3d p = pose.translation();
    const double r2 = options_.radius * options_.radius;
    std::vector<std::pair<double, int>> candidates;
    for (int j = 0; j <= index - options_.frame_distance; ++j) {
      const double d2 = (poses_[j].translation() - p).squaredNorm();
      if (d2 > r2) continue;
      if (YawDifferenceDeg(pose, poses_[j], options_.vertical) > options_.max_yaw_difference_deg)
        continue;
      candidates.emplace_back(d2, j);
    }
    const std::size_t n = std::min(candidates.size(), static_cast<std::size_t>(options_.attempts));
    std::partial_sort(candidates.begin(), candidates.begin() + static_cast<long>(n),
                      candidates.end());
    double best = -2;
    int best_j = -1;
    for (std::size_t c = 0; c < n; ++c) {
      const int j = candidates[c].second;
      const double q = UniversalQualityIndex(thumbnail, thumbnails_[j], options_.window);
      ++record.candidates;
      if (q >= options_.min_similarity && q > best) {
        best = q;
        best_j = j;
        if (options_.accept_first) break;
      }
    }
    if (best_j >= 0) {
      found = LoopPair{index, best_j, best};
      last_pinned_ = index;
      ++loops_closed_;
      record.loop = true;
    }
  }
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  records_.push_back(record);
  return found;
}

std::optional<LoopPair> OnlineSnaps::Step(const Eigen::Isometry3d& odometry_pose,
                                          const cv::Mat& thumbnail) {
  Eigen::Isometry3d pose = odometry_pose;
  pose.translation() += offset_;
  const int index = static_cast<int>(search_.poses().size());
  std::optional<LoopPair> loop = search_.Step(index, pose, thumbnail);
  if (loop) {
    const auto start = std::chrono::steady_clock::now();
    std::vector<Eigen::Isometry3d>& poses = search_.poses();
    const Eigen::Vector3d reference = poses[loop->reference].translation();
    offset_ +=
        ApplyDiscountedUpdate(poses, loop->query, reference, loop->similarity,
                              search_.loops_closed(), search_.options().discount.discount_length);
    correction_seconds_.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    loops_.push_back(*loop);
  }
  return loop;
}

LatencyStats Summarize(std::vector<double> seconds) {
  LatencyStats s;
  if (seconds.empty()) return s;
  std::sort(seconds.begin(), seconds.end());
  s.count = static_cast<int>(seconds.size());
  s.mean = std::accumulate(seconds.begin(), seconds.end(), 0.0) / s.count;
  auto quantile = [&](double f) {
    const double pos = f * (s.count - 1);
    const int lo = static_cast<int>(std::floor(pos));
    const int hi = std::min(lo + 1, s.count - 1);
    return seconds[lo] + (pos - lo) * (seconds[hi] - seconds[lo]);
  };
  s.min = seconds.front();
  s.q1 = quantile(0.25);
  s.median = quantile(0.5);
  s.q3 = quantile(0.75);
  s.max = seconds.back();
  return s;
}

}  // namespace openable::snaps
