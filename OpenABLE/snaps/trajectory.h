// Trajectories for the SNAPS add-on: poses of a camera over a run, their files, their
// association with a ground truth, and the absolute trajectory error.
//
// Paper: "Similarity and Location-based Real-time Loop Closure: SNAPS for SLAM in Unexplored
// Environments", Sec. II-III.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable::snaps {

// File formats.
//  - kKitti: one pose per line, 12 numbers, row-major 3x4 [R | t]; pose i is frame i.
//  - kKittiWithId: a frame number, then the 12 numbers (keyframes of a VO system, e.g. the
//    SO-DSO files of ../shared/datasets/kitti_trajectories); pose i is frame id_i.
//  - kTum: `timestamp tx ty tz qx qy qz qw` per line ('#' comments); pose i is frame i.
enum class TrajectoryFormat { kKitti, kKittiWithId, kTum };
OPENABLE_ENUM_NAMES(TrajectoryFormat, "kitti", "kitti-id", "tum")

// "kitti", "kitti-id", "tum" (case-insensitive); throws InputError naming `key` otherwise.
inline TrajectoryFormat ParseTrajectoryFormat(const std::string& name, const std::string& key) {
  return ParseEnum<TrajectoryFormat>(name, key);
}
inline std::string TrajectoryFormatName(TrajectoryFormat format) { return EnumName(format); }

struct Trajectory {
  TrajectoryFormat format = TrajectoryFormat::kKitti;
  // Camera-to-world poses (the camera's position is poses[i].translation()).
  std::vector<Eigen::Isometry3d> poses;
  // Frame number of each pose: the line index (kKitti, kTum) or the first column (kKittiWithId),
  // strictly increasing.
  std::vector<long> frame_ids;
  // Seconds, kTum only (empty otherwise).
  std::vector<double> timestamps;
  // The file stored world-to-camera matrices (inverted on reading, re-inverted on writing).
  bool world_to_camera = false;

  int Size() const { return static_cast<int>(poses.size()); }
};

// The largest |R^T R - I| of a 3x3 matrix taken for a rotation (files and programs round their
// numbers; a larger deviation is not a rotation).
// (The same value as the pose reader's, kPoseRotationTolerance in evaluation/pose_file.h.)
inline constexpr double kRotationTolerance = 1e-3;

// The camera-to-world pose [r | t]: `r` must be a rotation within kRotationTolerance
// (orthonormal, determinant +1), made exactly orthonormal (the nearest rotation) when it is not
// one to 1e-12, and `t` finite. Throws InputError "<where>: the 3x3 part is not a rotation
// (...)" or "<where>: the translation is not finite" otherwise. Every pose that enters a
// trajectory (files, the Python module) passes here.
Eigen::Isometry3d CheckedPose(const Eigen::Matrix3d& r, const Eigen::Vector3d& t,
                              const std::string& where);

// Checks a trajectory built in memory (the Python module) as a file is checked when read: one
// frame id per pose, strictly increasing; timestamps (required for kTum) one per pose, finite and
// strictly increasing, so that what EncodeTrajectory writes reads back. Throws InputError
// "<what>: ..." naming the value.
void CheckTrajectory(const Trajectory& trajectory, const std::string& what);

// Reads a trajectory with the pose reader the evaluation's ground truth uses too
// (OpenABLE/evaluation/pose_file.h, ReadPoseFile). `world_to_camera`: the file's matrices map
// world points into the camera (SO-DSO's poses_history_file.txt); they are inverted so that
// `poses` are camera-to-world. Throws InputError naming the file and the line (wrong count of
// numbers, not a number, non-finite value, a rotation that is not one within 1e-3, frame ids or
// timestamps not increasing, empty or missing file).
Trajectory ReadTrajectory(const std::string& path, TrajectoryFormat format,
                          bool world_to_camera = false);

// The trajectory in its own format (and orientation convention), full double precision, so that
// ReadTrajectory(EncodeTrajectory(t)) gives t back.
std::string EncodeTrajectory(const Trajectory& trajectory);

// For each pose of `estimate`, the index of its pose in `truth`: by frame id (kKitti and
// kKittiWithId against a per-frame ground truth), or by nearest timestamp within
// `time_tolerance` seconds (both kTum). Throws InputError naming `key` when a pose has no
// counterpart (the message gives the first such frame and the ground truth's range).
std::vector<int> AssociateWithTruth(const Trajectory& estimate, const Trajectory& truth,
                                    double time_tolerance, const std::string& key);

// Absolute trajectory error of the positions of `estimate` against their counterparts in
// `truth` (`association` as AssociateWithTruth gives it).
struct TrajectoryError {
  double rmse = 0;  // sqrt(mean of squared distances), metres
  double mean = 0;  // mean distance: the paper's "mean deviation from the ground truth"
  double median = 0;
  double max = 0;
  bool aligned = false;  // a rigid alignment was applied first
  Eigen::Isometry3d alignment = Eigen::Isometry3d::Identity();  // applied to the estimate
};
// `align` = true: first the rigid motion (rotation + translation, no scale) that best maps the
// estimate's positions onto the truth's in the least-squares sense (Umeyama, Eigen::umeyama).
TrajectoryError AbsoluteTrajectoryError(const Trajectory& estimate, const Trajectory& truth,
                                        const std::vector<int>& association, bool align);

// The words of ConventionHint in the caller's terms: openable_snaps' keys, Python's arguments.
struct ConventionWords {
  const char* estimate;         // the trajectory evaluated: "the input"
  const char* world_to_camera;  // the setting that inverts the file's matrices
  const char* on;               // its value that does: "1", "True"
  const char* formats;          // the settings of both files' formats
};
inline constexpr ConventionWords kChainConventionWords = {
    "the input", "Snaps_world_to_camera", "1",
    "Snaps_trajectory_format and Snaps_ground_truth_format"};

// A hint at the conventions when the estimate cannot be a drifting estimate of the truth's
// route: its mean error after rigid alignment (`aligned`, AbsoluteTrajectoryError with align)
// exceeds a quarter of the route's extent, the diagonal of the bounding box of the truth's
// positions. Such an error comes from a convention (world-to-camera matrices read as
// camera-to-world, the wrong format) or files of different frames, not from drift. One line
// naming the settings as `words` gives them; empty otherwise. openable_snaps prints it after
// "Hint: "; Python's trajectory_error and snaps.run give it as a warning.
std::string ConventionHint(const TrajectoryError& aligned, const Trajectory& truth,
                           const ConventionWords& words = kChainConventionWords);

// A loop: pose `query` (the later one) revisits the place of pose `reference` (indices into
// the trajectory, reference < query). `similarity` in [0, 1] (Q of the paper; 1 when unknown).
struct LoopPair {
  int query = 0;
  int reference = 0;
  double similarity = 1.0;
};

}  // namespace openable::snaps
