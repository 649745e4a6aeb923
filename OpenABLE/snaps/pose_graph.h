// Pose-graph correction of a drifting trajectory with loop pairs (the SNAPS add-on): the
// least-squares alternative to the SNAPS paper's discounted update (Sec. II-C, Eq. 6). Odometry
// edges between consecutive poses (6-DoF); loop edges on position only, under a robust kernel,
// since a loop pair says "same place" and not the relative rotation; pose 0 fixed. Solved by
// iteratively reweighted Levenberg-Marquardt on an Eigen sparse LDLT. The default weights are
// the orders of a stereo VO's error per keyframe (0.02 m, 0.001 rad) and of a loop (1 m), so
// loops correct heading drift rather than bend the path locally. Residuals, kernels, solver and
// defaults: docs/snaps.md, "Pose-graph correction".
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

enum class RobustKernel { kNone, kHuber, kCauchy };
OPENABLE_ENUM_NAMES(RobustKernel, "none", "huber", "cauchy")

// "none", "huber", "cauchy" (case-insensitive); InputError naming `key` otherwise.
inline RobustKernel ParseRobustKernel(const std::string& name, const std::string& key) {
  return ParseEnum<RobustKernel>(name, key);
}
inline std::string RobustKernelName(RobustKernel kernel) { return EnumName(kernel); }

struct PoseGraphOptions {
  // Information of an odometry edge's translation residual, 1/m^2 (> 0). 2500 = sigma 0.02 m.
  double odometry_translation_weight = 2500.0;
  // Information of an odometry edge's rotation residual, 1/rad^2 (> 0). 1e6 = sigma 0.001 rad.
  double odometry_rotation_weight = 1e6;
  // Information of a loop edge's position residual, 1/m^2 (> 0). 1 = sigma 1 m.
  double loop_weight = 1.0;
  // Multiply each loop's weight by its similarity (LoopPair::similarity, in [0, 1]).
  bool use_similarity = false;
  // Robust kernel on loop edges, and its scale in whitened units (sqrt(loop_weight) x metres;
  // > 0).
  RobustKernel robust_kernel = RobustKernel::kHuber;
  double robust_scale = 3.0;
  // Stop when (cost_before - cost_after) / cost_before < relative_tolerance (>= 0), or after
  // max_iterations (>= 1) accepted or rejected steps.
  double relative_tolerance = 1e-9;
  int max_iterations = 100;
  // Initial Levenberg-Marquardt damping (>= 0; 0 = start as Gauss-Newton).
  double initial_lambda = 1e-6;

  // InputError naming the key and the field ("Snaps_loop_weight
  // (PoseGraphOptions.loop_weight)"; the field alone when no key sets it) of a value out of
  // range. Defined in options.cc.
  void Check() const;
};

// A loop with a known relative pose: reference_from_query = T_reference^-1 T_query. Its edge has
// the odometry form, weighted w_L for translation and w_R x (w_L / w_t) for rotation.
struct RelativeLoop {
  int query = 0;
  int reference = 0;
  Eigen::Isometry3d reference_from_query = Eigen::Isometry3d::Identity();
};

struct PoseGraphReport {
  int iterations = 0;       // steps tried (accepted or rejected)
  int loop_edges = 0;       // loop edges in the graph (LoopPair + RelativeLoop)
  double initial_cost = 0;  // robustified cost of the input (0.5 x sum of weighted squares)
  double final_cost = 0;    // of the output
  double seconds = 0;       // wall time of the whole correction
  bool converged = false;   // stopped by relative_tolerance (not max_iterations)
};

// The corrected trajectory: `input` with its poses replaced by the minimiser of the pose graph
// (frame ids, timestamps, format and orientation convention kept). Without loops, or with fewer
// than two poses, the output equals the input. Throws std::logic_error when a loop index is out
// of range or query == reference; InputError when `options` fail Check().
Trajectory CorrectPoseGraph(const Trajectory& input, const std::vector<LoopPair>& loops,
                            const PoseGraphOptions& options, PoseGraphReport* report = nullptr);
// The same with loops whose relative pose is known as well.
Trajectory CorrectPoseGraph(const Trajectory& input, const std::vector<LoopPair>& loops,
                            const std::vector<RelativeLoop>& relative_loops,
                            const PoseGraphOptions& options, PoseGraphReport* report = nullptr);

}  // namespace openable::snaps
