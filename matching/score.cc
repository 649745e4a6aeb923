#include "matching/score.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"

namespace openable {
namespace {

// The ratio of a best distance to its rival; 1 when there is none or it is 0.
float Ratio(float best, float rival) {
  if (!std::isfinite(rival) || rival <= 0.0f) return 1.0f;
  return best / rival;
}

}  // namespace

int BestCandidate(const float* distances, int count) {
  int best = -1;
  for (int c = 0; c < count; ++c)
    if (std::isfinite(distances[c]) && (best < 0 || distances[c] < distances[best])) best = c;
  return best;
}

void MatchScoreOptions::Check() const { CheckIntRange("Match_score_window", window, 0, 100000); }

void MatchScoreOptions::CheckRivals(int references, const std::string& where) const {
  if (kind == MatchScore::kRatio && window >= references)
    throw InputError("Match_score_window: " + std::to_string(window) +
                     " frames is not smaller than the " + std::to_string(references) +
                     " frames of the reference traversal" +
                     (where.empty() ? "" : " (" + where + ")") +
                     "; expected a window that leaves rivals outside it for Match_score ratio "
                     "(10 frames is typical), or Match_score distance");
}

float ScoreOfCandidate(const float* distances, int count, int best,
                       const MatchScoreOptions& score) {
  const int window = score.window;
  if (score.kind == MatchScore::kDistance) return distances[best];
  float rival = std::numeric_limits<float>::infinity();
  for (int c = 0; c < count; ++c)
    if (std::abs(c - best) > window && distances[c] < rival) rival = distances[c];
  return Ratio(distances[best], rival);
}

float ScoreOfCandidate(const std::vector<std::pair<float, int>>& candidates, std::size_t best,
                       const MatchScoreOptions& score) {
  const auto [distance, frame] = candidates[best];
  const int window = score.window;
  if (score.kind == MatchScore::kDistance) return distance;
  float rival = std::numeric_limits<float>::infinity();
  for (const auto& [d, f] : candidates)
    if (std::abs(f - frame) > window && d < rival) rival = d;
  return Ratio(distance, rival);
}

std::vector<std::size_t> DistinctBest(const std::vector<std::pair<float, int>>& candidates, int k,
                                      int window) {
  std::vector<std::size_t> order;
  order.reserve(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (std::isfinite(candidates[i].first)) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return candidates[a] < candidates[b];  // distance, then frame
  });
  std::vector<std::size_t> taken;
  for (const std::size_t i : order) {
    if (static_cast<int>(taken.size()) >= k) break;
    bool near = false;
    for (const std::size_t t : taken)
      near = near || std::abs(candidates[t].second - candidates[i].second) <= window;
    if (!near) taken.push_back(i);
  }
  return taken;
}

}  // namespace openable
