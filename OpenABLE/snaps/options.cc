// The Check() of the SNAPS option structs, apart from the code that uses them, so that
// checking a configuration links none of it.
#include "OpenABLE/snaps/options.h"

#include "OpenABLE/base/option_checks.h"

namespace openable::snaps {

void DiscountOptions::Check() const {
  CheckIntAtLeast("Snaps_discount_length", discount_length, 0);
  CheckIntAtLeast("Snaps_pause", pause, 0);
}

void SearchOptions::Check() const {
  CheckNumberRange("Snaps_thumbnail_scale", thumbnail_scale, 0.01, 1);
  CheckIntRange("Snaps_window", window, 2, 64);
  CheckNumberRange("Snaps_min_similarity", min_similarity, -1, 1);
  CheckNumberRange("Snaps_yaw_limit", max_yaw_difference_deg, 0, 180);
  CheckNumberAtLeast("Snaps_radius", radius, 0);
  CheckIntAtLeast("Snaps_frame_distance", frame_distance, 1);
  CheckIntAtLeast("Snaps_attempts", attempts, 1);
  discount.Check();
}

void PoseGraphOptions::Check() const {
  const std::string o = "PoseGraphOptions.";
  CheckNumberAtLeast("Snaps_odometry_translation_weight (" + o + "odometry_translation_weight)",
                     odometry_translation_weight, 0, /*lo_excluded=*/true);
  CheckNumberAtLeast("Snaps_odometry_rotation_weight (" + o + "odometry_rotation_weight)",
                     odometry_rotation_weight, 0, true);
  CheckNumberAtLeast("Snaps_loop_weight (" + o + "loop_weight)", loop_weight, 0, true);
  CheckNumberAtLeast("Snaps_robust_scale (" + o + "robust_scale)", robust_scale, 0, true);
  CheckNumberAtLeast(o + "relative_tolerance", relative_tolerance, 0);
  CheckIntAtLeast(o + "max_iterations", max_iterations, 1);
  CheckNumberAtLeast(o + "initial_lambda", initial_lambda, 0);
}

void SnapsOptions::Check() const {
  CheckNumberAtLeast("Snaps_time_tolerance", time_tolerance, 0);
  CheckIntAtLeast("Snaps_keyframe_tolerance", keyframe_tolerance, 0);
  CheckNumberRange("Snaps_matrix_threshold", matrix_threshold, 0, 1);
  search.Check();
  pose_graph.Check();
}

}  // namespace openable::snaps
