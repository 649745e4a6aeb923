#include "matching/score.h"

#include <cmath>
#include <cstdlib>

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

float ScoreOfCandidate(const float* distances, int count, int best, MatchScore score,
                       int window) {
  if (score == MatchScore::kDistance) return distances[best];
  float rival = std::numeric_limits<float>::infinity();
  for (int c = 0; c < count; ++c)
    if (std::abs(c - best) > window && distances[c] < rival) rival = distances[c];
  return Ratio(distances[best], rival);
}

float ScoreOfCandidate(const std::vector<std::pair<float, int>>& candidates, std::size_t best,
                       MatchScore score, int window) {
  const auto [distance, frame] = candidates[best];
  if (score == MatchScore::kDistance) return distance;
  float rival = std::numeric_limits<float>::infinity();
  for (const auto& [d, f] : candidates)
    if (std::abs(f - frame) > window && d < rival) rival = d;
  return Ratio(distance, rival);
}

}  // namespace openable
