#include "OpenABLE/snaps/discounted.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace openable::snaps {

double DiscountGamma(int s_prime, int alpha) {
  if (s_prime < 0 || alpha < 1)
    throw std::invalid_argument("DiscountGamma: need s' >= 0 and alpha >= 1");
  const double g = 1.0 - 1.0 / std::exp(3.0 - alpha * 0.01 * s_prime);
  return std::max(0.0, g);
}

Eigen::Vector3d ApplyDiscountedUpdate(std::vector<Eigen::Isometry3d>& poses, int n,
                                      const Eigen::Vector3d& reference_position, double q,
                                      int alpha, int k) {
  const int size = static_cast<int>(poses.size());
  if (n < 0 || n >= size)
    throw std::invalid_argument("ApplyDiscountedUpdate: frame " + std::to_string(n) +
                                " outside a trajectory of " + std::to_string(size) + " poses");
  if (k < 0 || alpha < 1)
    throw std::invalid_argument("ApplyDiscountedUpdate: need K >= 0 and alpha >= 1");
  const Eigen::Vector3d delta = reference_position - poses[n].translation();
  for (int s = std::max(0, n - k); s <= n; ++s)
    poses[s].translation() += q * DiscountGamma(n - s, alpha) * delta;
  const Eigen::Vector3d shift = q * DiscountGamma(0, alpha) * delta;
  for (int t = n + 1; t < size; ++t) poses[t].translation() += shift;
  return shift;
}

Eigen::Vector3d ApplyDiscountedUpdate(Trajectory& trajectory, int n, int reference, double q,
                                      int alpha, int k) {
  if (reference < 0 || reference >= n || n >= trajectory.Size())
    throw std::invalid_argument("ApplyDiscountedUpdate: need 0 <= reference < N < size, got " +
                                std::to_string(reference) + ", " + std::to_string(n) + ", " +
                                std::to_string(trajectory.Size()));
  const Eigen::Vector3d ref = trajectory.poses[reference].translation();
  return ApplyDiscountedUpdate(trajectory.poses, n, ref, q, alpha, k);
}

std::vector<LoopPair> ClosedLoops(const std::vector<LoopPair>& loops, int pause) {
  std::vector<LoopPair> sorted = loops;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const LoopPair& a, const LoopPair& b) { return a.query < b.query; });
  std::vector<LoopPair> closed;
  for (const LoopPair& l : sorted) {
    if (!closed.empty() && l.query - closed.back().query <= pause) continue;
    closed.push_back(l);
  }
  return closed;
}

Trajectory CorrectDiscounted(const Trajectory& input, const std::vector<LoopPair>& loops,
                             const DiscountOptions& options) {
  for (const LoopPair& l : loops)
    if (l.reference < 0 || l.reference >= l.query || l.query >= input.Size())
      throw std::invalid_argument("CorrectDiscounted: loop (" + std::to_string(l.query) + ", " +
                                  std::to_string(l.reference) + ") invalid for " +
                                  std::to_string(input.Size()) + " poses");
  Trajectory out = input;
  int alpha = 0;
  for (const LoopPair& l : ClosedLoops(loops, options.pause))
    ApplyDiscountedUpdate(out, l.query, l.reference, l.similarity, ++alpha,
                          options.discount_length);
  return out;
}

}  // namespace openable::snaps
