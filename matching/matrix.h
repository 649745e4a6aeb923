// The distance matrix of a set of descriptor rows, from the kernels of this folder: every pair
// compared (Hamming, L2 or the sub-panorama comparison), sequences summed, Eq. 5 applied.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "matching/agreement.h"
#include "matching/contrast.h"
#include "matching/distances.h"
#include "matching/panorama.h"
#include "matching/score.h"
#include "matching/sequence.h"

namespace openable {

// How the frames of a run are compared (the keys Image_sequences, Sequence_direction,
// Panorama_matching, Threshold and Threads).
struct MatchingOptions {
  int sequence_length = 1;  // L: single-frame distances summed along a diagonal, 1..100000
  SequenceDirection direction = SequenceDirection::kForward;  // diagonals, anti-diagonals, both
  SequencePartial partial = SequencePartial::kAhead;          // cells with fewer than L terms
  PanoramaMatching panorama_matching = PanoramaMatching::kCrossCorrelation;  // panoramic frames
  double threshold = -1.0;  // theta of Eq. 9: -1 (no thresholded matrix) or a number in [0, 1]
  int threads = 0;          // worker threads for description and matching, 0..1024, 0 = all
  // The confidence of a best match and its rivals' window (matching/score.h).
  MatchScoreOptions score;
  // A query's best match is accepted when its score is <= this; -1: no threshold (in [0, 1]).
  double match_threshold = -1.0;
  // n: an accepted best match also needs the best matches of n independent queries (one
  // sequence apart, matching/agreement.h) to agree with it; 0: the score alone (0..1000).
  int match_consistency = 0;
  // SeqSLAM's local contrast enhancement of the single-frame matrix (matching/contrast.h).
  ContrastOptions contrast;
  // Several descriptors fused (Image_descriptor "HOG+LDB"): the weight of each normalised
  // single-frame matrix, comma-separated, in the order of the names; empty: equal weights.
  std::string fusion_weights;

  // The weights of `descriptors` fused descriptors (FusionWeights): equal weights when
  // fusion_weights is empty. Throws InputError naming Fusion_weights when they do not parse,
  // are not positive, or are not one per descriptor.
  std::vector<double> FusionWeights(int descriptors) const;
  // Throws InputError naming the key of a value out of range.
  void Check() const;
};

// The agreement of best matches under these options (matching/agreement.h): L, Sequence_partial
// and Sequence_direction, and Match_consistency partners (at least 1).
AgreementOptions AgreementOf(const MatchingOptions& options);

// Every row of `rows` against every row with `metric` (Distances), or, with strips > 1
// (panoramic frames), PanoramaDistances with `mode`.
cv::Mat1f PairwiseDistances(const cv::Mat& rows, Metric metric, int strips = 1,
                            PanoramaMatching mode = PanoramaMatching::kAligned, int threads = 0,
                            const PairProgress& progress = {});
// The same with the metric of the rows' type (Hamming for CV_8U, L2 for CV_32F).
cv::Mat1f PairwiseDistances(const cv::Mat& rows, int strips = 1,
                            PanoramaMatching mode = PanoramaMatching::kAligned, int threads = 0,
                            const PairProgress& progress = {});

// The sequence matrix of a run in one pass (SequenceMatrix of matching/bounded.h, traversal
// by traversal): the distances of rows of `rows` are computed a few at a time while they are
// in cache, summed along their diagonals as they come and the largest finite sum kept, with no
// single-frame matrix in memory. The same floats as PairwiseDistances followed by
// SequenceDistancesInPlace for the integer distances (Hamming, L1: their double sums are
// exact); L2 rows keep the two passes, whose tiles a run spread over processes computes the
// same way (matching/distances.h). `largest` receives the largest finite sum.
cv::Mat1f FusedSequenceMatrix(const cv::Mat& rows, Metric metric, int sequence_length,
                              SequenceDirection direction, SequencePartial partial,
                              const std::vector<int>& traversal_starts, int threads, float& largest,
                              const std::function<void(int, int)>& progress = {});

// M' of Eq. 5 of a single-camera run: PairwiseDistances (with `metric`, or the rows' type's),
// the sequence sums of sequence.h over
// the traversals that start at `traversal_starts` (when L > 1 or not forward), divided by
// their largest value. `max_distance` receives that divisor when given.
cv::Mat1f NormalizedDistanceMatrix(const cv::Mat& rows, int sequence_length,
                                   SequenceDirection direction,
                                   const std::vector<int>& traversal_starts, int threads,
                                   float* max_distance = nullptr, std::optional<Metric> metric = {},
                                   SequencePartial partial = SequencePartial::kAhead);

}  // namespace openable
