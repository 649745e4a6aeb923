// Pose-graph correction of a drifting trajectory with loop pairs (the SNAPS add-on).
//
// The SNAPS paper (Sec. II-C, Eq. 6) corrects the
// trajectory with a discounted update; this is the classical alternative it is compared with:
// a least-squares pose graph (see docs/snaps.md, "Pose-graph correction").
//
// Model. Nodes: the camera-to-world poses T_i = [R_i | t_i] of the input, i = 0 .. N-1.
//  - Odometry edge (i, i+1), one per consecutive pair: the relative pose Z_i = T_i^-1 T_{i+1}
//    measured by the input. Residual (6-DoF)
//        e_t = R_i^T (t_{i+1} - t_i) - t_Z          (metres, in the frame of camera i)
//        e_R = Log(R_Z^T R_i^T R_{i+1})              (radians, axis-angle)
//    cost w_t |e_t|^2 + w_R |e_R|^2 with w_t = odometry_translation_weight,
//    w_R = odometry_rotation_weight (information = diag(w_t I3, w_R I3)).
//  - Loop edge (query q, reference r): the two cameras are at the same place. A loop pair only
//    says "same place", not the relative rotation, so the residual is the position difference
//        e = t_q - t_r                                (metres, world frame)
//    cost rho(w_L |e|^2), w_L = loop_weight x the pair's similarity (when
//    use_similarity), rho the robust kernel. A known relative pose (a RelativeLoop, e.g. from
//    geometric verification) gives an edge of the odometry form instead, weighted by w_L for
//    both parts' translation and w_R x (w_L / w_t) for rotation.
//  - Gauge: pose 0 is fixed (the corrected trajectory starts where the input does).
// Robust kernel (loop edges only) on the whitened residual norm s = sqrt(w_L) |e|, scale c =
// robust_scale (in the same whitened unit: with the default loop_weight 1 it is metres):
// Huber rho(s^2) = s^2 for s <= c, 2 c s - c^2 beyond; Cauchy rho(s^2) = c^2 log(1 + s^2/c^2).
// Solved by iteratively reweighted Levenberg-Marquardt: Gauss-Newton steps on the right
// perturbation T_i <- T_i [Exp(phi_i) | rho_i] (rotation and translation increments in the
// camera frame), normal equations in an Eigen sparse matrix factorised by SimplicialLDLT (AMD
// ordering, symbolic analysis done once), damping lambda diag(H) raised when a step does not
// lower the cost. Stops when the relative decrease of the cost is below
// relative_tolerance, or after max_iterations.
//
// Defaults, and why: per keyframe step (~1 m on KITTI), a stereo VO's relative error is of the
// order of one or two centimetres and a twentieth of a degree, hence sigma_t = 0.02 m,
// sigma_R = 0.001 rad (w = 1 / sigma^2); a ground-truth loop pair of KITTI says "within a few
// metres", hence sigma_L = 1 m (w_L = 1) and a Huber scale of 3 (sigma units): a correct pair is
// quadratic, a wrong one pulls with a bounded force. With these weights the loops move mostly the
// rotations (drift of a VO is mostly heading), which is what corrects a drifting trajectory
// rather than bending it locally (a rotation is the cheaper correction beyond a lever arm of
// sqrt(w_R / w_t) = 20 m).
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

// A loop with a known relative pose: reference_from_query = T_reference^-1 T_query.
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

// The corrected trajectory: `input` with its poses replaced by the minimiser of the model above
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
