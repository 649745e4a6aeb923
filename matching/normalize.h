// Normalisation (Eq. 5 of the OpenABLE paper) and thresholding (Eq. 9).
#pragma once

#include <opencv2/core.hpp>

namespace openable {

// Eq. 5: M' = M / max(M). Returns max(M), the largest finite entry. A matrix whose maximum is 0
// (every frame identical) is left at 0. +inf entries (sequence cells skipped at the start of a
// traversal, matching/sequence.h) stay +inf. Throws std::logic_error on a negative or NaN
// entry.
float NormalizeByMax(cv::Mat1f& m);

// The two steps of NormalizeByMax, for a matrix held in shares (a run spread over processes):
// the largest finite entry of one share (0 when empty; std::logic_error on a negative or NaN
// entry), and the division of a share by the largest of all (nothing when it is 0).
float LargestFiniteEntry(const cv::Mat1f& m);
void DivideByLargest(cv::Mat1f& m, float largest);

// Eq. 9: M'' = 0 where M' < theta, 1 otherwise. 0 marks a loop candidate (a small distance).
cv::Mat1b ThresholdMatrix(const cv::Mat1f& normalized, float theta);

}  // namespace openable
