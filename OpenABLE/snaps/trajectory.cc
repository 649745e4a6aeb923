// Trajectory files (kitti, kitti-id, tum), association with a ground truth, absolute trajectory
// error. See trajectory.h and docs/snaps.md ("Trajectories", "Trajectory error").
#include "OpenABLE/snaps/trajectory.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/pose_file.h"

namespace openable::snaps {

static_assert(kRotationTolerance == kPoseRotationTolerance,
              "SNAPS and the pose reader take the same matrices for rotations");

namespace {

// The shortest text that reads back as `v` (for messages).
std::string Short(double v) { return ShortestNumber(v); }

std::string G17(double v) { return FormatNumber(v, 17); }

Eigen::Isometry3d Inverse(const Eigen::Isometry3d& t) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = t.linear().transpose();
  out.translation() = -(out.linear() * t.translation());
  return out;
}

}  // namespace

Eigen::Isometry3d CheckedPose(const Eigen::Matrix3d& r, const Eigen::Vector3d& t,
                              const std::string& where) {
  if (!t.allFinite()) throw InputError(where + ": the translation is not finite");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = CheckedRotationMatrix(r, where);
  pose.translation() = t;
  return pose;
}

void CheckTrajectory(const Trajectory& t, const std::string& what) {
  const std::size_t n = t.poses.size();
  if (t.frame_ids.size() != n)
    throw InputError(what + ": " + std::to_string(t.frame_ids.size()) +
                     " frame ids; expected one per pose (" + std::to_string(n) + ")");
  for (std::size_t i = 1; i < n; ++i)
    if (t.frame_ids[i] <= t.frame_ids[i - 1])
      throw InputError(what + ": frame " + std::to_string(t.frame_ids[i]) + " after frame " +
                       std::to_string(t.frame_ids[i - 1]) +
                       "; expected strictly increasing frame numbers");
  if (t.timestamps.empty()) {
    if (t.format == TrajectoryFormat::kTum)
      throw InputError(what + ": no timestamps; expected one per pose for format \"tum\"");
    return;
  }
  if (t.timestamps.size() != n)
    throw InputError(what + ": " + std::to_string(t.timestamps.size()) +
                     " timestamps; expected one per pose (" + std::to_string(n) + ")");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t.timestamps[i]))
      throw InputError(what + ": timestamp " + Short(t.timestamps[i]) + " (pose " +
                       std::to_string(i) + "); expected finite seconds");
    if (i > 0 && !(t.timestamps[i] > t.timestamps[i - 1]))
      throw InputError(what + ": timestamp " + Short(t.timestamps[i]) + " after " +
                       Short(t.timestamps[i - 1]) + " (pose " + std::to_string(i) +
                       "); expected strictly increasing timestamps");
  }
}

Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format, bool world_to_camera) {
  // The reader and checks the evaluation's ground truth uses too (pose_file.h).
  const PoseFileFormat file_format = format == TrajectoryFormat::kKitti ? PoseFileFormat::kKitti
                                     : format == TrajectoryFormat::kKittiWithId
                                         ? PoseFileFormat::kKittiWithId
                                         : PoseFileFormat::kTum;
  Trajectory trajectory;
  trajectory.format = format;
  trajectory.world_to_camera = world_to_camera;
  for (const PoseFileLine& line :
       ReadPoseFile(path, file_format, "trajectory", /*both_kitti=*/true)) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = line.rotation;
    pose.translation() = line.translation;
    if (world_to_camera) pose = Inverse(pose);
    trajectory.poses.push_back(pose);
    trajectory.frame_ids.push_back(line.frame_id);
    if (format == TrajectoryFormat::kTum) trajectory.timestamps.push_back(line.timestamp);
  }
  return trajectory;
}

std::string EncodeTrajectory(const Trajectory& trajectory) {
  const bool tum = trajectory.format == TrajectoryFormat::kTum;
  if (tum && trajectory.timestamps.size() != trajectory.poses.size()) {
    throw std::logic_error("EncodeTrajectory: a tum trajectory needs one timestamp per pose");
  }
  if (trajectory.format == TrajectoryFormat::kKittiWithId &&
      trajectory.frame_ids.size() != trajectory.poses.size()) {
    throw std::logic_error("EncodeTrajectory: a kitti-id trajectory needs one frame id per pose");
  }
  std::string out;
  if (tum) out += "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i < trajectory.Size(); ++i) {
    const Eigen::Isometry3d pose =
        trajectory.world_to_camera ? Inverse(trajectory.poses[i]) : trajectory.poses[i];
    std::string line;
    if (tum) {
      const Eigen::Quaterniond q(pose.linear());
      const Eigen::Vector3d& t = pose.translation();
      line = G17(trajectory.timestamps[i]);
      for (const double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) line += " " + G17(v);
    } else {
      if (trajectory.format == TrajectoryFormat::kKittiWithId) {
        line = std::to_string(trajectory.frame_ids[i]);
      }
      for (int k = 0; k < 12; ++k) {
        if (!line.empty()) line += ' ';
        line += G17(k % 4 == 3 ? pose.translation()(k / 4) : pose.linear()(k / 4, k % 4));
      }
    }
    out += line + '\n';
  }
  return out;
}

std::vector<int> AssociateWithTruth(const Trajectory& estimate, const Trajectory& truth,
                                    double time_tolerance, const std::string& key) {
  std::vector<int> association(estimate.poses.size(), -1);
  if (truth.poses.empty()) throw InputError(key + ": the ground truth has no pose");
  const bool by_time =
      estimate.format == TrajectoryFormat::kTum && truth.format == TrajectoryFormat::kTum;
  if (by_time) {
    const std::vector<double>& t = truth.timestamps;
    for (int i = 0; i < estimate.Size(); ++i) {
      const double s = estimate.timestamps[i];
      const auto it = std::lower_bound(t.begin(), t.end(), s);
      int best = -1;
      double best_gap = 0;
      for (auto c : {it, it == t.begin() ? t.end() : it - 1}) {
        if (c == t.end()) continue;
        const double gap = std::abs(*c - s);
        if (best < 0 || gap < best_gap) {
          best = static_cast<int>(c - t.begin());
          best_gap = gap;
        }
      }
      if (best < 0 || !(best_gap <= time_tolerance)) {
        throw InputError(key + ": timestamp " + Short(s) + " (pose " + std::to_string(i) +
                         ") has no ground-truth pose within " + Short(time_tolerance) +
                         " s; expected timestamps within the ground truth's " + Short(t.front()) +
                         " .. " + Short(t.back()) + " s");
      }
      association[i] = best;
    }
    return association;
  }
  const std::vector<long>& ids = truth.frame_ids;
  for (int i = 0; i < estimate.Size(); ++i) {
    const long id = estimate.frame_ids[i];
    const auto it = std::lower_bound(ids.begin(), ids.end(), id);
    if (it == ids.end() || *it != id) {
      throw InputError(key + ": frame " + std::to_string(id) + " (pose " + std::to_string(i) +
                       ") has no ground-truth pose; expected frames within the ground truth's " +
                       std::to_string(ids.front()) + " .. " + std::to_string(ids.back()));
    }
    association[i] = static_cast<int>(it - ids.begin());
  }
  return association;
}

TrajectoryError AbsoluteTrajectoryError(const Trajectory& estimate, const Trajectory& truth,
                                        const std::vector<int>& association, bool align) {
  const int n = estimate.Size();
  if (static_cast<int>(association.size()) != n || n == 0) {
    throw std::logic_error("AbsoluteTrajectoryError: one association per pose is needed (" +
                           std::to_string(association.size()) + " for " + std::to_string(n) +
                           " poses)");
  }
  Eigen::Matrix3Xd source(3, n), target(3, n);
  for (int i = 0; i < n; ++i) {
    const int j = association[i];
    if (j < 0 || j >= truth.Size()) {
      throw std::logic_error("AbsoluteTrajectoryError: association out of range");
    }
    source.col(i) = estimate.poses[i].translation();
    target.col(i) = truth.poses[j].translation();
  }
  TrajectoryError error;
  error.aligned = align;
  if (align) {
    const Eigen::Matrix4d m = Eigen::umeyama(source, target, false);
    error.alignment.matrix() = m;
    source = (m.topLeftCorner<3, 3>() * source).colwise() + m.topRightCorner<3, 1>();
  }
  std::vector<double> d(n);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    d[i] = (source.col(i) - target.col(i)).norm();
    sum += d[i];
    sum2 += d[i] * d[i];
  }
  error.rmse = std::sqrt(sum2 / n);
  error.mean = sum / n;
  error.max = *std::max_element(d.begin(), d.end());
  std::sort(d.begin(), d.end());
  error.median = n % 2 == 1 ? d[n / 2] : 0.5 * (d[n / 2 - 1] + d[n / 2]);
  return error;
}

std::string ConventionHint(const TrajectoryError& aligned, const Trajectory& truth,
                           const ConventionWords& words) {
  if (truth.poses.empty()) return "";
  Eigen::Vector3d lo = truth.poses.front().translation(), hi = lo;
  for (const Eigen::Isometry3d& p : truth.poses) {
    lo = lo.cwiseMin(p.translation());
    hi = hi.cwiseMax(p.translation());
  }
  const double extent = (hi - lo).norm();
  if (!(extent > 0 && aligned.mean > 0.25 * extent)) return "";
  return std::string(words.estimate) + " is " + FormatFixed(aligned.mean, 1) +
         " m from the ground truth on average even after alignment, on a route " +
         FormatFixed(extent, 1) + " m across: more than drift. Check " + words.world_to_camera +
         " (" + words.on +
         " when the file holds world-to-camera matrices, as SO-DSO's poses_history_file.txt), " +
         words.formats + ", and that both cover the same frames.";
}

}  // namespace openable::snaps
