// The distance matrix of a set of descriptor rows, from the kernels of this folder: every pair
// compared (Hamming, L2 or the sub-panorama comparison), sequences summed, Eq. 5 applied.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "matching/distances.h"
#include "matching/panorama.h"
#include "matching/sequence.h"

namespace openable {

// How the frames of a run are compared (the keys Image_sequences, Sequence_direction,
// Panorama_matching, Threshold and Threads).
struct MatchingOptions {
  int sequence_length = 1;  // L: single-frame distances summed along a diagonal, 1..100000
  SequenceDirection direction = SequenceDirection::kForward;  // diagonals, anti-diagonals, both
  PanoramaMatching panorama_matching = PanoramaMatching::kCrossCorrelation;  // panoramic frames
  double threshold = -1.0;  // theta of Eq. 9: -1 (no thresholded matrix) or a number in [0, 1]
  int threads = 0;          // worker threads for description and matching, 0..1024, 0 = all

  // Throws InputError naming the key of a value out of range.
  void Check() const;
};

// Every row of `rows` against every row: HammingDistances for CV_8U rows, L2Distances for
// CV_32F rows, or, with strips > 1 (panoramic frames), PanoramaDistances with `mode`.
cv::Mat1f PairwiseDistances(const cv::Mat& rows, int strips = 1,
                            PanoramaMatching mode = PanoramaMatching::kAligned, int threads = 0,
                            const PairProgress& progress = {});

// M' of Eq. 5 of a single-camera run: PairwiseDistances, the sequence sums of sequence.h over
// the traversals that start at `traversal_starts` (when L > 1 or not forward), divided by
// their largest value. `max_distance` receives that divisor when given.
cv::Mat1f NormalizedDistanceMatrix(const cv::Mat& rows, int sequence_length,
                                   SequenceDirection direction,
                                   const std::vector<int>& traversal_starts, int threads,
                                   float* max_distance = nullptr);

}  // namespace openable
