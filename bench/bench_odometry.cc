// Monocular odometry on KITTI 00 frames 0-1699 (../shared/datasets/kitti00_first1700,
// half-size left frames), the scale of each step taken from the ground truth's step lengths (a
// single camera cannot know it). Prints the per-frame time (mean, quartiles), the absolute
// trajectory error (mean deviation, unaligned and rigidly aligned), the final drift, and writes
// the trajectory in KITTI format.
//
// Usage: bench_odometry OUTPUT_POSES.txt [FIRST LAST [ORB|SIFT [RANSAC_PX [MAX_FEATURES]]]]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/odometry/calibration.h"
#include "OpenABLE/odometry/mono_odometry.h"
#include "OpenABLE/snaps/trajectory.h"

namespace {

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double x = q * (v.size() - 1);
  const auto i = static_cast<std::size_t>(x);
  return i + 1 < v.size() ? v[i] + (x - i) * (v[i + 1] - v[i]) : v[i];
}

}  // namespace

int main(int argc, char** argv) {
  using namespace openable;
  if (argc < 2) {
    std::cerr << "usage: bench_odometry OUTPUT_POSES.txt [FIRST LAST [ORB|SIFT [RANSAC_PX "
                 "[MAX_FEATURES]]]]\n";
    return 2;
  }
  const std::string dir = std::string(OPENABLE_DATASETS_DIR) + "/kitti00_first1700";
  if (!std::filesystem::exists(dir)) {
    std::cout << "dataset absent: " << dir << "\n";
    return 0;
  }
  const int first = argc >= 4 ? std::stoi(argv[2]) : 0;
  const int last = argc >= 4 ? std::stoi(argv[3]) : 1699;
  odometry::MonoOdometryOptions options;
  if (argc >= 5) options.features = argv[4];
  if (argc >= 6) options.ransac_threshold_px = std::stod(argv[5]);
  if (argc >= 7) options.max_features = std::stoi(argv[6]);
  try {
    const odometry::KittiCalibration calibration =
        odometry::ReadKittiCalibration(dir + "/calib.txt", 0.5);
    const snaps::Trajectory truth =
        snaps::ReadTrajectory(dir + "/poses/00_first1700.txt", snaps::TrajectoryFormat::kKitti);
    odometry::MonoOdometry mono(calibration.left, options);
    snaps::Trajectory estimate;
    std::vector<double> seconds;
    int failed = 0, inliers = 0;
    // The ground truth's first pose of the range is the odometry's identity: express the
    // estimate in the ground truth's world so that the unaligned error is meaningful.
    const Eigen::Isometry3d origin = truth.poses[first];
    for (int i = first; i <= last; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "/image_0/%06d.png", i);
      const cv::Mat gray = cv::imread(dir + name, cv::IMREAD_GRAYSCALE);
      if (gray.empty()) throw InputError(dir + name + ": cannot read");
      const double step =
          i == first ? 0.0
                     : (truth.poses[i].translation() - truth.poses[i - 1].translation()).norm();
      const Eigen::Isometry3d pose = mono.Step(gray, step);
      estimate.poses.push_back(origin * pose);
      estimate.frame_ids.push_back(i);
      if (i > first) {
        seconds.push_back(mono.last().seconds);
        inliers += mono.last().inliers;
        if (!mono.last().ok && ++failed <= 5)
          std::printf("frame %d: %s\n", i, mono.last().note.c_str());
      }
    }
    std::ofstream out(argv[1]);
    out << snaps::EncodeTrajectory(estimate);
    if (!out) throw InputError(std::string(argv[1]) + ": cannot write");
    const std::vector<int> association =
        snaps::AssociateWithTruth(estimate, truth, 0.0, "ground truth");
    const auto unaligned = snaps::AbsoluteTrajectoryError(estimate, truth, association, false);
    const auto aligned = snaps::AbsoluteTrajectoryError(estimate, truth, association, true);
    double length = 0;
    for (int i = first + 1; i <= last; ++i)
      length += (truth.poses[i].translation() - truth.poses[i - 1].translation()).norm();
    const double drift =
        (estimate.poses.back().translation() - truth.poses[last].translation()).norm();
    // Per-step errors of the relative motions (frame i-1 to i): rotation angle of
    // R_true^T R_estimated, and the angle between the translation directions (steps > 0.1 m).
    double rotation_error = 0, direction_error = 0;
    int directions = 0;
    for (int i = first + 1; i <= last; ++i) {
      const Eigen::Isometry3d e =
          estimate.poses[i - first - 1].inverse() * estimate.poses[i - first];
      const Eigen::Isometry3d g = truth.poses[i - 1].inverse() * truth.poses[i];
      rotation_error += odometry::RotationAngle(g.linear().transpose() * e.linear());
      if (g.translation().norm() > 0.1 && e.translation().norm() > 0) {
        const double c = g.translation().normalized().dot(e.translation().normalized());
        direction_error += std::acos(std::clamp(c, -1.0, 1.0));
        ++directions;
      }
    }
    constexpr double kDegrees = 180.0 / 3.14159265358979323846;
    double mean = 0;
    for (double s : seconds) mean += s;
    mean /= std::max<std::size_t>(1, seconds.size());
    std::printf("MonoOdometry %s, KITTI 00 frames %d-%d (%.0f m), ground-truth step lengths\n",
                options.features.c_str(), first, last, length);
    std::printf("per-frame time: mean %.4f s, quartiles %.4f / %.4f / %.4f s\n", mean,
                Quantile(seconds, 0.25), Quantile(seconds, 0.5), Quantile(seconds, 0.75));
    std::printf("mean inliers %.0f, fallback steps %d of %zu\n",
                inliers / std::max(1.0, double(seconds.size())), failed, seconds.size());
    std::printf(
        "per-step errors: rotation %.3f deg (mean), translation direction %.2f deg (mean)\n",
        kDegrees * rotation_error / std::max(1, last - first),
        kDegrees * direction_error / std::max(1, directions));
    std::printf("ATE unaligned: mean %.2f m, rmse %.2f m, max %.2f m\n", unaligned.mean,
                unaligned.rmse, unaligned.max);
    std::printf("ATE aligned:   mean %.2f m, rmse %.2f m, max %.2f m\n", aligned.mean, aligned.rmse,
                aligned.max);
    std::printf("final drift: %.2f m (%.2f %% of the length)\n", drift, 100 * drift / length);
    std::printf("trajectory written to %s (KITTI format)\n", argv[1]);
  } catch (const InputError& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
