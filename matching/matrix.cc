#include "matching/matrix.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/strings.h"
#include "matching/bounded.h"
#include "matching/large_matrix.h"
#include "matching/normalize.h"

namespace openable {

void MatchingOptions::Check() const {
  CheckIntRange("Image_sequences", sequence_length, 1, 100000);
  if (threshold != -1.0 && !(threshold >= 0.0 && threshold <= 1.0))
    throw InputError("Threshold: " + FormatNumber(threshold) +
                     " is not valid; expected -1 (disabled) or a number in [0, 1]");
  CheckIntRange("Threads", threads, 0, 1024);
  score.Check();
  if (match_threshold != -1.0 && !(match_threshold >= 0.0 && match_threshold <= 1.0))
    throw InputError("Match_threshold: " + FormatNumber(match_threshold) +
                     " is not valid; expected -1 (none) or a number in [0, 1]");
  CheckIntRange("Match_consistency", match_consistency, 0, 1000);
  contrast.Check();
  if (!fusion_weights.empty()) FusionWeights(-1);
}

AgreementOptions AgreementOf(const MatchingOptions& options) {
  AgreementOptions a;
  a.sequence_length = options.sequence_length;
  a.partial = options.partial;
  a.direction = options.direction;
  a.partners = options.match_consistency > 0 ? options.match_consistency : 1;
  return a;
}

std::vector<double> MatchingOptions::FusionWeights(int descriptors) const {
  const auto fail = [&](const std::string& why) {
    throw InputError("Fusion_weights: " + Quoted(fusion_weights) + " is not valid (" + why +
                     "); expected one weight > 0 per fused descriptor, comma-separated, e.g. "
                     "\"1,0.5\"");
  };
  if (fusion_weights.empty()) return std::vector<double>(std::max(descriptors, 0), 1.0);
  std::vector<double> weights;
  std::stringstream ss(fusion_weights);
  for (std::string item; std::getline(ss, item, ',');) {
    item = Trim(item);
    char* end = nullptr;
    const double w = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) fail(Quoted(item) + " is not a number");
    if (!(w > 0) || !std::isfinite(w)) fail(item + " is not > 0");
    weights.push_back(w);
  }
  if (fusion_weights.back() == ',') fail("empty item");
  if (descriptors >= 0 && static_cast<int>(weights.size()) != descriptors)
    fail(std::to_string(weights.size()) + " weights for " + std::to_string(descriptors) +
         " descriptors");
  return weights;
}

cv::Mat1f PairwiseDistances(const cv::Mat& rows, Metric metric, int strips, PanoramaMatching mode,
                            int threads, const PairProgress& progress) {
  if (strips > 1) return PanoramaDistances(rows, strips, mode, threads, progress, metric);
  return Distances(rows, cv::Mat(), metric, threads, progress);
}

cv::Mat1f PairwiseDistances(const cv::Mat& rows, int strips, PanoramaMatching mode, int threads,
                            const PairProgress& progress) {
  return PairwiseDistances(rows, MetricOfType(rows.type()), strips, mode, threads, progress);
}

cv::Mat1f FusedSequenceMatrix(const cv::Mat& rows, Metric metric, int sequence_length,
                              SequenceDirection direction, SequencePartial partial,
                              const std::vector<int>& traversal_starts, int threads, float& largest,
                              const std::function<void(int, int)>& progress) {
  if (metric == Metric::kL2)
    throw std::logic_error("FusedSequenceMatrix: L2 rows take PairwiseDistances");
  const int n = rows.rows;
  CheckTraversalStarts(traversal_starts, n, "traversal_starts");
  std::vector<int> bounds = traversal_starts.empty() ? std::vector<int>{0} : traversal_starts;
  bounds.push_back(n);
  const int traversals = static_cast<int>(bounds.size()) - 1;
  cv::Mat1f out = LargeMatrix(n, n);
  BoundedOptions options;
  options.metric = metric;
  options.sequence_length = sequence_length;
  options.direction = direction;
  options.partial = partial;
  options.threads = threads;
  largest = 0.0f;
  // Each block of (query traversal, reference traversal) apart: sums never cross traversals.
  // Progress in rows of the whole matrix.
  int rows_before = 0;
  for (int r = 0; r < traversals; ++r) {
    for (int c = 0; c < traversals; ++c) {
      MatchBlock block;
      block.query_first = bounds[static_cast<size_t>(r)];
      block.query_count = bounds[static_cast<size_t>(r) + 1] - block.query_first;
      block.reference_first = bounds[static_cast<size_t>(c)];
      block.reference_count = bounds[static_cast<size_t>(c) + 1] - block.reference_first;
      block.one_traversal = r == c;
      const int share = traversals;  // each query row is computed once per reference traversal
      const auto block_progress = [&](int done, int) {
        if (progress) progress((rows_before + done) / share, n);
      };
      largest = std::max(largest, SequenceMatrix(rows, block, options, out, block_progress));
      rows_before += block.query_count;
    }
  }
  if (progress) progress(n, n);
  return out;
}

cv::Mat1f NormalizedDistanceMatrix(const cv::Mat& rows, int sequence_length,
                                   SequenceDirection direction,
                                   const std::vector<int>& traversal_starts, int threads,
                                   float* max_distance, std::optional<Metric> metric,
                                   SequencePartial partial) {
  const Metric kind = metric.value_or(MetricOfType(rows.type()));
  cv::Mat1f d;
  float m = 0.0f;
  if (kind != Metric::kL2) {
    // Distances, sums and the largest value in one pass, then one scaling pass.
    d = FusedSequenceMatrix(rows, kind, sequence_length, direction, partial, traversal_starts,
                            threads, m);
    DivideByLargest(d, m);
  } else {
    d = PairwiseDistances(rows, kind, 1, PanoramaMatching::kAligned, threads);
    if (sequence_length > 1 || direction != SequenceDirection::kForward)
      SequenceDistancesInPlace(d, sequence_length, traversal_starts, traversal_starts, direction,
                               threads, partial);
    m = NormalizeByMax(d);
  }
  if (max_distance != nullptr) *max_distance = m;
  return d;
}

}  // namespace openable
