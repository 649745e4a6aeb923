// Rows of random descriptors for the matching tests, from fixed seeds.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <random>

namespace openable::matching_test {

// `rows` x `cols` random bytes (CV_8U): binary descriptors of 8 `cols` bits.
inline cv::Mat RandomBytes(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat m(rows, cols, CV_8U);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m.at<std::uint8_t>(i, j) = static_cast<std::uint8_t>(rng());
  return m;
}

// `rows` x `cols` floats (CV_32F), each `offset` plus a normal deviate of deviation `sigma`.
inline cv::Mat RandomFloats(int rows, int cols, unsigned seed, float offset = 0, float sigma = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, sigma);
  cv::Mat m(rows, cols, CV_32F);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m.at<float>(i, j) = offset + normal(rng);
  return m;
}

}  // namespace openable::matching_test
