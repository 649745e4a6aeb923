// The one reader of pose files, shared by the evaluation's ground truth (Ground_truth_type
// kitti and tum, openable_evaluate, openable.evaluate) and SNAPS' trajectories
// (OpenABLE/snaps/trajectory.h: Snaps_trajectory, Snaps_ground_truth, openable.snaps): one
// format, one set of checks.
//
//  - kitti: 12 numbers per line, the row-major 3x4 camera-to-world matrix [R | t];
//  - kitti-id: a frame number, then the 12 numbers (frame numbers strictly increasing);
//  - tum: "timestamp tx ty tz qx qy qz qw" (timestamps strictly increasing).
// Blank lines and lines starting with '#' are skipped; numbers are separated by blanks. R (or
// the quaternion) must be a rotation within kPoseRotationTolerance; it is made exactly
// orthonormal (the nearest rotation) when it is not already within 1e-12.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace openable {

enum class PoseFileFormat { kKitti, kKittiWithId, kTum };

// The largest |R^T R - I| (and | |q| - 1 |) of a pose taken for a rotation: files round their
// numbers; a larger deviation is not a rotation.
inline constexpr double kPoseRotationTolerance = 1e-3;

struct PoseFileLine {
  int line = 0;          // line of the file, from 1
  long frame_id = 0;     // kitti-id: the first column; otherwise the pose's index (0, 1, ...)
  double timestamp = 0;  // tum: seconds
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // as written (camera-to-world)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

// Reads every pose of `path`. `what` names the file in messages ("KITTI poses", "trajectory").
// Throws InputError "<what> "<path>":<line>: ..." naming the value and what was expected: a
// missing or unreadable file, a line with the wrong count of numbers, a value that is not a
// finite number, a frame number that is not a non-negative integer or does not increase, a
// timestamp that does not increase, a matrix that is not a rotation (orthonormal with
// determinant +1), a quaternion that is not of unit norm, and a file with no pose.
// `both_kitti`: the caller reads kitti and kitti-id alike (SNAPS' trajectories), so a line
// with the other one's count of numbers (13 for kitti, 12 for kitti-id) names that format.
std::vector<PoseFileLine> ReadPoseFile(const std::string& path, PoseFileFormat format,
                                       const std::string& what, bool both_kitti = false);

// The nearest rotation to `m` when it is one within kPoseRotationTolerance (orthonormal,
// determinant +1); throws InputError "<where>: the 3x3 part is not a rotation ..." otherwise.
Eigen::Matrix3d CheckedRotationMatrix(const Eigen::Matrix3d& m, const std::string& where);

// The shortest text that reads back as `v` (numbers in the messages of pose files).
std::string ShortestNumber(double v);

}  // namespace openable
