// Pose-graph correction: see the model in pose_graph.h.
#include "OpenABLE/snaps/pose_graph.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable::snaps {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// A change of the cost below this is rounding (the cost is 0 for a consistent graph).
constexpr double kNegligibleCost = 1e-18;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Vector3d Log(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d Exp(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}

// Inverse of the right Jacobian of SO(3) at `phi`.
Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d k = Skew(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * k + k * k / 12.0;
  const double c = 1.0 / (theta * theta) - (1 + std::cos(theta)) / (2 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * k + c * k * k;
}

// One edge between poses i and j. kind Relative: residual [R_i^T (t_j - t_i) - t_Z;
// Log(R_Z^T R_i^T R_j)] with weights (w_t x3, w_R x3). kind Position: residual [t_j - t_i; 0]
// with weights (w x3, 0 x3); j is the query, i the reference.
struct Edge {
  enum Kind { kRelative, kPosition } kind = kRelative;
  int i = 0, j = 0;
  Eigen::Isometry3d z = Eigen::Isometry3d::Identity();
  Vector6d weights = Vector6d::Zero();
  bool robust = false;
  // Blocks of the normal matrix this edge adds to (-1 when a pose is the fixed one).
  int block_ii = -1, block_jj = -1, block_ij = -1, block_ji = -1;
};

struct Linearised {
  Vector6d e;
  Matrix6d ji, jj;  // d e / d delta_i, d e / d delta_j (delta = [rho; phi])
};

Vector6d Residual(const Edge& edge, const std::vector<Eigen::Isometry3d>& poses) {
  const Eigen::Isometry3d& ti = poses[edge.i];
  const Eigen::Isometry3d& tj = poses[edge.j];
  Vector6d e = Vector6d::Zero();
  if (edge.kind == Edge::kPosition) {
    e.head<3>() = tj.translation() - ti.translation();
    return e;
  }
  const Eigen::Matrix3d ri_t = ti.linear().transpose();
  e.head<3>() = ri_t * (tj.translation() - ti.translation()) - edge.z.translation();
  e.tail<3>() = Log(edge.z.linear().transpose() * ri_t * tj.linear());
  return e;
}

Linearised Linearise(const Edge& edge, const std::vector<Eigen::Isometry3d>& poses) {
  const Eigen::Isometry3d& ti = poses[edge.i];
  const Eigen::Isometry3d& tj = poses[edge.j];
  Linearised l;
  l.e = Residual(edge, poses);
  l.ji.setZero();
  l.jj.setZero();
  if (edge.kind == Edge::kPosition) {
    // t <- t + R rho.
    l.ji.topLeftCorner<3, 3>() = -ti.linear();
    l.jj.topLeftCorner<3, 3>() = tj.linear();
    return l;
  }
  const Eigen::Matrix3d ri_t = ti.linear().transpose();
  const Eigen::Vector3d v = ri_t * (tj.translation() - ti.translation());
  const Eigen::Matrix3d jr_inv = RightJacobianInverse(l.e.tail<3>());
  l.ji.topLeftCorner<3, 3>() = -Eigen::Matrix3d::Identity();
  l.ji.topRightCorner<3, 3>() = Skew(v);
  l.ji.bottomRightCorner<3, 3>() = -jr_inv * tj.linear().transpose() * ti.linear();
  l.jj.topLeftCorner<3, 3>() = ri_t * tj.linear();
  l.jj.bottomRightCorner<3, 3>() = jr_inv;
  return l;
}

// rho(s2) and rho'(s2) of the kernel, s2 the whitened squared norm.
void Kernel(RobustKernel kernel, double c, double s2, double* rho, double* weight) {
  switch (kernel) {
    case RobustKernel::kNone:
      break;
    case RobustKernel::kHuber:
      if (s2 > c * c) {
        const double s = std::sqrt(s2);
        *rho = 2 * c * s - c * c;
        *weight = c / s;
        return;
      }
      break;
    case RobustKernel::kCauchy:
      *rho = c * c * std::log1p(s2 / (c * c));
      *weight = 1.0 / (1.0 + s2 / (c * c));
      return;
  }
  *rho = s2;
  *weight = 1.0;
}

double Cost(const std::vector<Edge>& edges, const std::vector<Eigen::Isometry3d>& poses,
            const PoseGraphOptions& options) {
  double cost = 0;
  for (const Edge& edge : edges) {
    const Vector6d e = Residual(edge, poses);
    const double s2 = e.dot(edge.weights.cwiseProduct(e));
    double rho = s2, weight = 1;
    if (edge.robust) Kernel(options.robust_kernel, options.robust_scale, s2, &rho, &weight);
    cost += 0.5 * rho;
  }
  return cost;
}

// Normal equations over poses 1 .. N-1 (pose 0 is the gauge), in a fixed sparse pattern of 6x6
// blocks; block_start[b][c] is the index in the value array of the block's first row in its
// column c.
class NormalEquations {
 public:
  NormalEquations(int poses, std::vector<Edge>& edges) : n_(6 * (poses - 1)) {
    std::unordered_map<long long, int> index;
    std::vector<std::pair<int, int>> blocks;  // (block row, block column)
    const auto block = [&](int a, int b) {
      if (a <= 0 || b <= 0) return -1;
      const long long key = static_cast<long long>(a - 1) * poses + (b - 1);
      const auto it = index.find(key);
      if (it != index.end()) return it->second;
      const int id = static_cast<int>(blocks.size());
      index.emplace(key, id);
      blocks.emplace_back(a - 1, b - 1);
      return id;
    };
    for (int p = 1; p < poses; ++p) block(p, p);
    for (Edge& e : edges) {
      e.block_ii = block(e.i, e.i);
      e.block_jj = block(e.j, e.j);
      e.block_ij = block(e.i, e.j);
      e.block_ji = block(e.j, e.i);
    }
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(36 * blocks.size());
    for (const auto& [a, b] : blocks) {
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) triplets.emplace_back(6 * a + r, 6 * b + c, 0.0);
    }
    h_.resize(n_, n_);
    h_.setFromTriplets(triplets.begin(), triplets.end());
    h_.makeCompressed();
    block_start_.resize(blocks.size());
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const auto [a, b] = blocks[k];
      for (int c = 0; c < 6; ++c) {
        const int col = 6 * b + c;
        const int* rows = h_.innerIndexPtr();
        const int begin = h_.outerIndexPtr()[col], end = h_.outerIndexPtr()[col + 1];
        block_start_[k][c] =
            static_cast<int>(std::lower_bound(rows + begin, rows + end, 6 * a) - rows);
      }
    }
    diagonal_.resize(n_);
    for (int k = 0; k < n_; ++k) {
      const int* rows = h_.innerIndexPtr();
      const int begin = h_.outerIndexPtr()[k], end = h_.outerIndexPtr()[k + 1];
      diagonal_[k] = static_cast<int>(std::lower_bound(rows + begin, rows + end, k) - rows);
    }
    b_.resize(n_);
  }

  void Clear() {
    std::fill(h_.valuePtr(), h_.valuePtr() + h_.nonZeros(), 0.0);
    b_.setZero();
  }
  void AddBlock(int block, const Matrix6d& m) {
    if (block < 0) return;
    double* values = h_.valuePtr();
    for (int c = 0; c < 6; ++c) {
      double* column = values + block_start_[block][c];
      for (int r = 0; r < 6; ++r) column[r] += m(r, c);
    }
  }
  void AddGradient(int pose, const Vector6d& g) {
    if (pose > 0) b_.segment<6>(6 * (pose - 1)) += g;
  }
  // H + lambda diag(H) (in place; Undamp() restores H).
  void Damp(double lambda) {
    saved_.resize(n_);
    for (int k = 0; k < n_; ++k) {
      double& d = h_.valuePtr()[diagonal_[k]];
      saved_[k] = d;
      d += lambda * std::max(d, 1e-12);
    }
  }
  void Undamp() {
    for (int k = 0; k < n_; ++k) h_.valuePtr()[diagonal_[k]] = saved_[k];
  }
  Eigen::SparseMatrix<double>& H() { return h_; }
  const Eigen::VectorXd& b() const { return b_; }

 private:
  int n_;
  Eigen::SparseMatrix<double> h_;
  Eigen::VectorXd b_;
  std::vector<std::array<int, 6>> block_start_;
  std::vector<int> diagonal_;
  std::vector<double> saved_;
};

std::vector<Eigen::Isometry3d> Apply(const std::vector<Eigen::Isometry3d>& poses,
                                     const Eigen::VectorXd& delta) {
  std::vector<Eigen::Isometry3d> out = poses;
  for (std::size_t p = 1; p < poses.size(); ++p) {
    const Vector6d d = delta.segment<6>(6 * (p - 1));
    Eigen::Isometry3d& t = out[p];
    t.translation() += t.linear() * d.head<3>();
    t.linear() = (t.linear() * Exp(d.tail<3>())).eval();
  }
  return out;
}

void CheckIndex(int index, int size, const char* what) {
  if (index < 0 || index >= size) {
    throw std::logic_error(std::string("CorrectPoseGraph: loop ") + what + " index " +
                           std::to_string(index) + " outside 0 .. " + std::to_string(size - 1));
  }
}

}  // namespace

Trajectory CorrectPoseGraph(const Trajectory& input, const std::vector<LoopPair>& loops,
                            const PoseGraphOptions& options, PoseGraphReport* report) {
  return CorrectPoseGraph(input, loops, {}, options, report);
}

Trajectory CorrectPoseGraph(const Trajectory& input, const std::vector<LoopPair>& loops,
                            const std::vector<RelativeLoop>& relative_loops,
                            const PoseGraphOptions& options, PoseGraphReport* report) {
  const auto start = std::chrono::steady_clock::now();
  options.Check();
  const int n = input.Size();
  for (const LoopPair& l : loops) {
    CheckIndex(l.query, n, "query");
    CheckIndex(l.reference, n, "reference");
    if (l.query == l.reference) throw std::logic_error("CorrectPoseGraph: loop query == reference");
  }
  for (const RelativeLoop& l : relative_loops) {
    CheckIndex(l.query, n, "query");
    CheckIndex(l.reference, n, "reference");
    if (l.query == l.reference) throw std::logic_error("CorrectPoseGraph: loop query == reference");
  }
  PoseGraphReport local;
  PoseGraphReport& r = report != nullptr ? *report : local;
  r = PoseGraphReport();
  r.loop_edges = static_cast<int>(loops.size() + relative_loops.size());
  Trajectory output = input;
  const auto finish = [&]() {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return output;
  };
  if (n < 2 || r.loop_edges == 0) {
    r.converged = true;
    return finish();
  }

  // Edges.
  std::vector<Edge> edges;
  edges.reserve(n - 1 + loops.size() + relative_loops.size());
  Vector6d odometry_weights;
  odometry_weights << Eigen::Vector3d::Constant(options.odometry_translation_weight),
      Eigen::Vector3d::Constant(options.odometry_rotation_weight);
  for (int i = 0; i + 1 < n; ++i) {
    Edge e;
    e.kind = Edge::kRelative;
    e.i = i;
    e.j = i + 1;
    e.z = input.poses[i].inverse(Eigen::Isometry) * input.poses[i + 1];
    e.weights = odometry_weights;
    edges.push_back(e);
  }
  for (const LoopPair& l : loops) {
    Edge e;
    e.kind = Edge::kPosition;
    e.i = l.reference;
    e.j = l.query;
    const double w =
        options.loop_weight * (options.use_similarity ? std::clamp(l.similarity, 0.0, 1.0) : 1.0);
    e.weights << Eigen::Vector3d::Constant(w), Eigen::Vector3d::Zero();
    e.robust = options.robust_kernel != RobustKernel::kNone;
    edges.push_back(e);
  }
  for (const RelativeLoop& l : relative_loops) {
    Edge e;
    e.kind = Edge::kRelative;
    e.i = l.reference;
    e.j = l.query;
    e.z = l.reference_from_query;
    const double scale = options.loop_weight / options.odometry_translation_weight;
    e.weights << Eigen::Vector3d::Constant(options.loop_weight),
        Eigen::Vector3d::Constant(options.odometry_rotation_weight * scale);
    e.robust = options.robust_kernel != RobustKernel::kNone;
    edges.push_back(e);
  }

  std::vector<Eigen::Isometry3d> poses = input.poses;
  NormalEquations normal(n, edges);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  solver.analyzePattern(normal.H());

  double cost = Cost(edges, poses, options);
  r.initial_cost = cost;
  double lambda = options.initial_lambda;
  bool relinearise = true;
  while (r.iterations < options.max_iterations && cost > 0) {
    if (relinearise) {
      normal.Clear();
      for (const Edge& edge : edges) {
        const Linearised l = Linearise(edge, poses);
        Vector6d w = edge.weights;
        if (edge.robust) {
          const double s2 = l.e.dot(edge.weights.cwiseProduct(l.e));
          double rho = 0, weight = 1;
          Kernel(options.robust_kernel, options.robust_scale, s2, &rho, &weight);
          w *= weight;
        }
        const Eigen::Matrix<double, 6, 6> wji = w.asDiagonal() * l.ji;
        const Eigen::Matrix<double, 6, 6> wjj = w.asDiagonal() * l.jj;
        normal.AddBlock(edge.block_ii, l.ji.transpose() * wji);
        normal.AddBlock(edge.block_jj, l.jj.transpose() * wjj);
        normal.AddBlock(edge.block_ij, l.ji.transpose() * wjj);
        normal.AddBlock(edge.block_ji, l.jj.transpose() * wji);
        normal.AddGradient(edge.i, wji.transpose() * l.e);
        normal.AddGradient(edge.j, wjj.transpose() * l.e);
      }
    }
    normal.Damp(lambda);
    solver.factorize(normal.H());
    normal.Undamp();
    ++r.iterations;
    if (solver.info() != Eigen::Success) {
      lambda = std::max(10 * lambda, 1e-4);
      relinearise = false;
      continue;
    }
    const Eigen::VectorXd delta = solver.solve(-normal.b());
    std::vector<Eigen::Isometry3d> trial = Apply(poses, delta);
    const double trial_cost = Cost(edges, trial, options);
    const double decrease = (cost - trial_cost) / cost;
    const bool negligible = std::abs(decrease) < options.relative_tolerance ||
                            std::abs(cost - trial_cost) < kNegligibleCost;
    if (trial_cost < cost) {
      poses.swap(trial);
      cost = trial_cost;
      lambda = lambda / 10;
      relinearise = true;
      if (negligible) {
        r.converged = true;
        break;
      }
    } else {
      if (negligible || lambda > 1e12) {
        r.converged = negligible;
        break;
      }
      lambda = std::max(10 * lambda, 1e-4);
      relinearise = false;
    }
  }
  if (cost == 0) r.converged = true;
  r.final_cost = cost;
  output.poses = poses;
  return finish();
}

}  // namespace openable::snaps
