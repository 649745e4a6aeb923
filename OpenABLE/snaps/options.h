// The SNAPS chain as the configuration gives it (the Snaps_* keys, docs/snaps.md): where the
// trajectory and the loops come from, how the trajectory is corrected, and what is written.
#pragma once

#include <string>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/snaps/loop_search.h"
#include "OpenABLE/snaps/pose_graph.h"
#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

// Where the loops come from (Snaps_loops): SNAPS's own search on thumbnails, a file of frame
// pairs, the matrix of an OpenABLE run saved earlier, or an OpenABLE run made here.
enum class LoopSource { kSearch, kPairs, kMatrix, kOpenable };
OPENABLE_ENUM_NAMES(LoopSource, "search", "pairs", "matrix", "openable")

// Which corrections run (Snaps_corrector): the paper's discounted update (Eq. 6), the pose
// graph, or both.
enum class Corrector { kDiscounted, kPoseGraph, kBoth };
OPENABLE_ENUM_NAMES(Corrector, "discounted", "pose-graph", "both")

// The ground plane of the plot and of the yaw (Snaps_axes): x-z (KITTI, y down) or x-y (z up).
enum class GroundPlane { kXz, kXy };
OPENABLE_ENUM_NAMES(GroundPlane, "xz", "xy")

struct SnapsOptions {
  std::string trajectory;  // the drifting trajectory to correct (unless computed by odometry)
  TrajectoryFormat trajectory_format = TrajectoryFormat::kKitti;
  bool world_to_camera = false;  // the file holds world-to-camera matrices (SO-DSO)
  std::string ground_truth;      // camera-to-world ground truth; empty: no evaluation
  TrajectoryFormat ground_truth_format = TrajectoryFormat::kKitti;
  double time_tolerance = 0.02;  // seconds, >= 0: TUM poses associated by timestamp
  LoopSource loops = LoopSource::kSearch;
  std::string loops_file;          // the pairs file or saved matrix of kPairs and kMatrix
  std::string frame_times;         // kMatrix: the matrix rows' times (Timestamps_name); empty: none
  int keyframe_tolerance = 0;      // frames, >= 0: a frame that is not a pose takes the nearest
  bool middle_of_runs = true;      // pairs: keep the middle reference of each run of references
  bool drop_outside = false;       // pairs: drop pairs outside the trajectory instead of failing
  double matrix_threshold = 0.15;  // matrix, openable: loops below this M', [0, 1]
  std::string images;              // image folder of the trajectory's frames; empty: Images_path
  SearchOptions search;            // SNAPS's search and its discounted update (Table I)
  Corrector corrector = Corrector::kBoth;
  PoseGraphOptions pose_graph;
  GroundPlane axes = GroundPlane::kXz;
  std::string output_name;  // output prefix; empty: figures printed only

  // Throws InputError naming the key of a value out of range (its own and those of search and
  // pose_graph). Which inputs a chain needs depends on other keys: CheckSnapsConfig
  // (config/config.h) checks them.
  void Check() const;
};

}  // namespace openable::snaps
