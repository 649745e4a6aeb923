// The bounded mode with approximate candidates (Approximate_search 1): the index of
// Approximate_engine (matching/search/approximate.h, an engine of
// matching/search/engine_registry.h) finds the candidates of each query; each candidate is then
// scored by its exact sequence sum (SequenceCellDistance). Declared in matching/bounded.h.
#include <algorithm>
#include <cmath>

#include "OpenABLE/base/threading.h"
#include "matching/bounded.h"
#include "matching/search/approximate.h"
#include "matching/sequence.h"

namespace openable {
namespace {

// Candidate lists (reference numbers) of every query, k per query, from the index of `options`
// (deterministic, so two runs give the same candidates).
std::vector<std::vector<int>> Candidates(const cv::Mat& refs, const cv::Mat& queries, int k,
                                         ApproximateOptions options, int threads) {
  options.k = k;
  options.threads = threads;
  const ApproximateIndex index(refs, options);
  const CandidateLists lists = index.Search(queries);
  std::vector<std::vector<int>> out(lists.size());
  for (size_t q = 0; q < lists.size(); ++q)
    for (const Candidate& c : lists[q]) out[q].push_back(c.reference);
  return out;
}

}  // namespace

std::vector<Match> ApproximateMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                      const KeepRules& rules, const BoundedOptions& options,
                                      const ApproximateOptions& approximate, float& max_distance) {
  const int L = options.sequence_length;
  const bool reverse = options.direction == SequenceDirection::kReverse;
  const bool both = options.direction == SequenceDirection::kBoth;
  const int m = block.reference_count;
  // One sequence: the candidates must lie Exclusion frames back; ask the index for that many
  // more.
  const int k = std::max(1, rules.best);
  const int asked = std::min(m, block.one_traversal ? k + 2 * rules.exclusion : k);
  const cv::Mat refs = descriptors.rowRange(block.reference_first, block.reference_first + m);
  const cv::Mat queries =
      descriptors.rowRange(block.query_first, block.query_first + block.query_count);
  // The share of the queries searched (BoundedOptions::query_begin/end); the sequences read
  // the rows before it.
  const int q_begin = std::clamp(options.query_begin, 0, block.query_count);
  const int q_end = options.query_end < 0
                        ? block.query_count
                        : std::clamp(options.query_end, q_begin, block.query_count);
  const std::vector<std::vector<int>> cand =
      Candidates(refs, queries.rowRange(q_begin, q_end), asked, approximate, options.threads);

  auto score = [&](int q, int j, bool rev) {
    return SequenceCellDistance(queries, q, refs, j, L, rev, nullptr, options.partial);
  };
  std::vector<std::vector<Match>> per_query(static_cast<size_t>(q_end - q_begin));
  ParallelFor(q_end - q_begin, options.threads, [&](int share_row) {
    const int q = q_begin + share_row;
    std::vector<std::pair<float, int>> scored;
    for (const int j : cand[static_cast<size_t>(share_row)]) {
      if (j < 0 || j >= m) continue;
      if (block.one_traversal && j > q - rules.exclusion) continue;
      const float s = both ? std::min(score(q, j, false), score(q, j, true)) : score(q, j, reverse);
      if (std::isfinite(s)) scored.emplace_back(s, j);
    }
    std::sort(scored.begin(), scored.end());
    // Ratio scores among every candidate scored (the search's, not every reference's).
    std::vector<float> scores(std::min(scored.size(), static_cast<size_t>(k)));
    for (size_t r = 0; r < scores.size(); ++r) scores[r] = ScoreOfCandidate(scored, r, rules.score);
    if (static_cast<int>(scored.size()) > k) scored.resize(static_cast<size_t>(k));
    auto& out = per_query[static_cast<size_t>(share_row)];
    for (size_t r = 0; r < scored.size(); ++r)
      out.push_back({q, scored[r].second, scored[r].first, static_cast<int>(r + 1), scores[r]});
  });
  std::vector<Match> kept;
  float max_seen = 0.0f;
  for (auto& v : per_query)
    for (Match& x : v) {
      max_seen = std::max(max_seen, x.distance);
      kept.push_back(x);
    }
  max_distance = max_seen;
  if (options.normalize) NormalizeMatches(kept, max_seen, rules.score);
  return kept;
}

}  // namespace openable
