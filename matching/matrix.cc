#include "matching/matrix.h"

#include "matching/normalize.h"

namespace openable {

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
