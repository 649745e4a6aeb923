#include "matching/bounded.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <stdexcept>

#include "OpenABLE/base/option_checks.h"
#include "matching/distances.h"
#include "matching/large_matrix.h"

namespace openable {

void KeepRules::Check() const {
  CheckIntRange("Best_matches", best, 0, 100000);
  CheckIntAtLeast("Band_width", band, -1);
  CheckIntAtLeast("Exclusion", exclusion, 1);
}

MatchBlock BlockOf(const std::vector<int>& starts, int n) {
  MatchBlock b;
  if (starts.size() <= 1) {
    b.query_count = b.reference_count = n;
    return b;
  }
  if (starts.size() != 2) throw std::logic_error("BlockOf: one or two traversals");
  b.one_traversal = false;
  b.reference_first = 0;
  b.reference_count = starts[1];
  b.query_first = starts[1];
  b.query_count = n - starts[1];
  return b;
}

void KeepRow(const float* s, int references, int q, const KeepRules& rules,
             std::vector<Match>& out) {
  // k best: a max-heap of (distance, reference) holding the k smallest seen; ties go to the
  // smaller reference number.
  const int limit = rules.one_traversal ? std::min(references, q - rules.exclusion + 1)
                                        : references;
  using Entry = std::pair<float, int>;
  std::priority_queue<Entry> heap;
  if (rules.best > 0) {
    for (int j = 0; j < limit; ++j) {
      if (!std::isfinite(s[j])) continue;
      const Entry e{s[j], j};
      if (static_cast<int>(heap.size()) < rules.best) {
        heap.push(e);
      } else if (e < heap.top()) {
        heap.pop();
        heap.push(e);
      }
    }
  }
  std::vector<Entry> best;
  best.reserve(heap.size());
  for (; !heap.empty(); heap.pop()) best.push_back(heap.top());
  std::reverse(best.begin(), best.end());
  const auto score = [&](int j) {
    return ScoreOfCandidate(s, std::max(0, limit), j, rules.score, rules.score_window);
  };
  for (size_t r = 0; r < best.size(); ++r)
    out.push_back({q, best[r].second, best[r].first, static_cast<int>(r + 1),
                   score(best[r].second)});
  if (rules.band >= 0) {
    const int j0 = std::max(0, q - rules.band), j1 = std::min(references - 1, q + rules.band);
    for (int j = j0; j <= j1; ++j) {
      const bool ranked = std::any_of(best.begin(), best.end(),
                                      [&](const Entry& e) { return e.second == j; });
      if (!ranked && std::isfinite(s[j])) out.push_back({q, j, s[j], 0, score(j)});
    }
  }
}

std::vector<Match> MatchesFromMatrix(const cv::Mat1f& normalized, const MatchBlock& block,
                                     const KeepRules& rules) {
  std::vector<Match> out;
  for (int q = 0; q < block.query_count; ++q)
    KeepRow(normalized.ptr<float>(block.query_first + q) + block.reference_first,
            block.reference_count, q, rules, out);
  return out;
}

std::vector<Match> BoundedMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                  const KeepRules& rules, const BoundedOptions& options,
                                  float& max_distance,
                                  const std::function<void(int, int)>& progress) {
  const int L = options.sequence_length;
  const int m = block.reference_count;
  const cv::Mat references = descriptors.rowRange(block.reference_first,
                                                  block.reference_first + m);
  const Metric metric = options.metric.value_or(MetricOfType(descriptors.type()));
  std::unique_ptr<HammingReferences> packed;
  if (metric == Metric::kHamming) packed = std::make_unique<HammingReferences>(references);
  // Rows per tile: the tile (with its L - 1 rows of history) within tile_bytes.
  const std::int64_t row_bytes = static_cast<std::int64_t>(m) * sizeof(float);
  const int tile_rows = static_cast<int>(std::max<std::int64_t>(
      16, options.tile_bytes / std::max<std::int64_t>(1, row_bytes) - (L - 1)));
  std::vector<Match> kept;
  float max_seen = 0.0f;
  cv::Mat1f tile;
  for (int r0 = 0; r0 < block.query_count; r0 += tile_rows) {
    const int r1 = std::min(block.query_count, r0 + tile_rows);
    const int h0 = std::max(0, r0 - (L - 1));  // history rows for the sequence sums
    const cv::Mat queries =
        descriptors.rowRange(block.query_first + h0, block.query_first + r1);
    if (packed) {
      packed->DistancesInto(queries, tile, options.threads);
    } else {
      tile = Distances(queries, references, metric, options.threads);
    }
    // Row h0 stands for the start of the query traversal: exact when h0 is 0, and rows from
    // r0 on have all L - 1 rows of history inside the tile otherwise.
    SequenceDistancesInPlace(tile, L, {0}, {0}, options.direction, options.threads,
                             options.partial);
    for (int r = r0; r < r1; ++r) {
      const float* s = tile.ptr<float>(r - h0);
      for (int j = 0; j < m; ++j)
        if (std::isfinite(s[j])) max_seen = std::max(max_seen, s[j]);
      KeepRow(s, m, r, rules, kept);
    }
    if (progress) progress(r1, block.query_count);
  }
  max_distance = max_seen;
  if (max_seen > 0.0f)
    for (Match& k : kept) k.distance /= max_seen;
  if (rules.score == MatchScore::kDistance)
    for (Match& k : kept) k.score = k.distance;
  return kept;
}

}  // namespace openable
