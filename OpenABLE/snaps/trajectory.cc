// Trajectory files (kitti, kitti-id, tum), association with a ground truth, absolute trajectory
// error. See trajectory.h and docs/snaps.md ("Trajectories", "Trajectory error").
#include "OpenABLE/snaps/trajectory.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "OpenABLE/base/error.h"

namespace openable::snaps {
namespace {

// Largest |R^T R - I| entry accepted as a rotation, and the one below which a rotation is kept
// as it is (so that a file written by EncodeTrajectory reads back to the same bits).
constexpr double kExactEnough = 1e-12;

std::string G17(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

// The shortest text that reads back as `v` (for messages).
std::string Short(double v) {
  char buffer[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", digits, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  return buffer;
}

// "file":line
std::string Where(const std::string& path, int line) {
  return Quoted(path) + ":" + std::to_string(line);
}

std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  std::string t;
  while (in >> t) out.push_back(t);
  return out;
}

// A finite double, or InputError naming the place, the token and its position.
double ParseNumber(const std::string& token, const std::string& where, int column,
                   const char* what) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0') {
    throw InputError(where + ": " + Quoted(token) + " (column " + std::to_string(column) +
                     ") is not a number; expected " + what);
  }
  if (!std::isfinite(v)) {
    throw InputError(where + ": " + Quoted(token) + " (column " + std::to_string(column) +
                     ") is not finite; expected a finite " + what);
  }
  return v;
}

long ParseFrameId(const std::string& token, const std::string& where) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE || v < 0) {
    throw InputError(where + ": " + Quoted(token) +
                     " (column 1) is not a frame number; expected a non-negative integer");
  }
  return v;
}

// The nearest rotation to `m` when it is one within kRotationTolerance; InputError otherwise.
Eigen::Matrix3d CheckedRotation(const Eigen::Matrix3d& m, const std::string& where) {
  const double deviation = (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = m.determinant();
  if (!(deviation <= kRotationTolerance) || det <= 0) {
    throw InputError(where + ": the 3x3 part is not a rotation (max |R^T R - I| = " +
                     Short(deviation) + ", det = " + Short(det) +
                     "); expected an orthonormal matrix with determinant +1 within " +
                     Short(kRotationTolerance));
  }
  if (deviation <= kExactEnough) return m;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

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
  pose.linear() = CheckedRotation(r, where);
  pose.translation() = t;
  return pose;
}

Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format,
                          bool world_to_camera) {
  std::ifstream in(path);
  if (!in) {
    throw InputError(Quoted(path) + ": cannot open the trajectory file (" +
                     TrajectoryFormatName(format) + " format); expected a readable text file");
  }
  Trajectory trajectory;
  trajectory.format = format;
  trajectory.world_to_camera = world_to_camera;
  const std::size_t expected = format == TrajectoryFormat::kKitti ? 12 : format ==
                                   TrajectoryFormat::kKittiWithId ? 13 : 8;
  const char* layout = format == TrajectoryFormat::kKitti
                           ? "12 numbers (row-major 3x4 [R | t])"
                           : format == TrajectoryFormat::kKittiWithId
                                 ? "13 numbers (frame number, row-major 3x4 [R | t])"
                                 : "8 numbers (timestamp tx ty tz qx qy qz qw)";
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;  // blank or comment
    const std::string where = Where(path, line_number);
    const std::vector<std::string> tokens = Tokens(line);
    if (tokens.size() != expected) {
      throw InputError(where + ": " + std::to_string(tokens.size()) + " values; expected " +
                       layout);
    }
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    long frame_id = trajectory.Size();
    double timestamp = 0;
    if (format == TrajectoryFormat::kTum) {
      timestamp = ParseNumber(tokens[0], where, 1, "timestamp (seconds)");
      double v[7];
      for (int k = 0; k < 7; ++k) v[k] = ParseNumber(tokens[k + 1], where, k + 2, "pose value");
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // w, x, y, z
      const double norm = q.norm();
      if (!(std::abs(norm - 1) <= kRotationTolerance)) {
        throw InputError(where + ": quaternion (" + tokens[4] + " " + tokens[5] + " " +
                         tokens[6] + " " + tokens[7] + ") has norm " + Short(norm) +
                         "; expected a unit quaternion within " + Short(kRotationTolerance));
      }
      pose.linear() = CheckedRotation(q.normalized().toRotationMatrix(), where);
      pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    } else {
      const int offset = format == TrajectoryFormat::kKittiWithId ? 1 : 0;
      if (offset == 1) frame_id = ParseFrameId(tokens[0], where);
      Eigen::Matrix<double, 3, 4> m;
      for (int k = 0; k < 12; ++k) {
        m(k / 4, k % 4) = ParseNumber(tokens[k + offset], where, k + offset + 1, "pose value");
      }
      pose.linear() = CheckedRotation(m.leftCols<3>(), where);
      pose.translation() = m.col(3);
    }
    if (world_to_camera) pose = Inverse(pose);
    if (!trajectory.frame_ids.empty() && frame_id <= trajectory.frame_ids.back()) {
      throw InputError(where + ": frame " + std::to_string(frame_id) + " after frame " +
                       std::to_string(trajectory.frame_ids.back()) +
                       "; expected strictly increasing frame numbers");
    }
    if (format == TrajectoryFormat::kTum && !trajectory.timestamps.empty() &&
        !(timestamp > trajectory.timestamps.back())) {
      throw InputError(where + ": timestamp " + tokens[0] + " after " +
                       Short(trajectory.timestamps.back()) +
                       "; expected strictly increasing timestamps");
    }
    trajectory.poses.push_back(pose);
    trajectory.frame_ids.push_back(frame_id);
    if (format == TrajectoryFormat::kTum) trajectory.timestamps.push_back(timestamp);
  }
  if (in.bad()) throw InputError(Quoted(path) + ": read error; expected a readable text file");
  if (trajectory.poses.empty()) {
    throw InputError(Quoted(path) + ":" + std::to_string(line_number) +
                     ": no pose in the file; expected lines of " + layout);
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
  const bool by_time = estimate.format == TrajectoryFormat::kTum &&
                       truth.format == TrajectoryFormat::kTum;
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

}  // namespace openable::snaps
