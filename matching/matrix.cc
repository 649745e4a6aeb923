#include "matching/matrix.h"

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/strings.h"
#include "matching/normalize.h"

namespace openable {

void MatchingOptions::Check() const {
  CheckIntRange("Image_sequences", sequence_length, 1, 100000);
  if (threshold != -1.0 && !(threshold >= 0.0 && threshold <= 1.0))
    throw InputError("Threshold: " + FormatNumber(threshold) +
                     " is not valid; expected -1 (disabled) or a number in [0, 1]");
  CheckIntRange("Threads", threads, 0, 1024);
}

cv::Mat1f PairwiseDistances(const cv::Mat& rows, int strips, PanoramaMatching mode, int threads,
                            const PairProgress& progress) {
  if (strips > 1) return PanoramaDistances(rows, strips, mode, threads, progress);
  return rows.depth() == CV_8U ? HammingDistances(rows, cv::Mat(), threads, progress)
                               : L2Distances(rows, cv::Mat(), threads, progress);
}

cv::Mat1f NormalizedDistanceMatrix(const cv::Mat& rows, int sequence_length,
                                   SequenceDirection direction,
                                   const std::vector<int>& traversal_starts, int threads,
                                   float* max_distance) {
  cv::Mat1f d = PairwiseDistances(rows, 1, PanoramaMatching::kAligned, threads);
  if (sequence_length > 1 || direction != SequenceDirection::kForward)
    SequenceDistancesInPlace(d, sequence_length, traversal_starts, traversal_starts, direction,
                             threads);
  const float m = NormalizeByMax(d);
  if (max_distance != nullptr) *max_distance = m;
  return d;
}

}  // namespace openable
