// Helpers shared by the descriptor tests: fixed-seed test patches and one-row description.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "descriptors/descriptor.h"

namespace openable {
namespace testing_util {

// A natural-looking grey patch: two scales of blurred Gaussian noise (coarse sigma size / 10,
// fine sigma 1.5) around 128, fixed seed. tests/data/ldb_reference.txt is made from these.
inline cv::Mat TexturedPatch(int size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(size, size, CV_32F), fine(size, size, CV_32F);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
  rng.fill(fine, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(coarse, coarse, cv::Size(0, 0), size / 10.0);
  cv::GaussianBlur(fine, fine, cv::Size(0, 0), 1.5);
  cv::normalize(coarse, coarse, -1.0, 1.0, cv::NORM_MINMAX);
  cv::normalize(fine, fine, -1.0, 1.0, cv::NORM_MINMAX);
  cv::Mat field = 128.0 + 80.0 * coarse + 25.0 * fine;
  cv::Mat out;
  field.convertTo(out, CV_8U);
  return out;
}

inline DescriptorOptions Options(int patch_size, int ldb_bits = 256) {
  DescriptorOptions o;
  o.patch_size = patch_size;
  o.ldb_bits = ldb_bits;
  return o;
}

// The descriptor row of `patch`, allocated here.
inline cv::Mat Describe(const Descriptor& d, const cv::Mat& patch) {
  cv::Mat row(1, d.Width(), RowType(d));
  d.Describe(patch, row);
  return row;
}

// Hamming distance of two binary rows counted bit by bit (independent of the popcount kernels).
inline int Hamming(const cv::Mat& a, const cv::Mat& b) {
  int bits = 0;
  for (int i = 0; i < a.cols; ++i) {
    const unsigned x = a.at<std::uint8_t>(0, i) ^ b.at<std::uint8_t>(0, i);
    for (int k = 0; k < 8; ++k) bits += static_cast<int>((x >> k) & 1u);
  }
  return bits;
}

// Mean Hamming distances over 8 textured patches (seeds patch_seed + i) between each patch and
// (a) itself with Gaussian noise of sigma 3 grey levels (drawn from noise_seed) and (b) an
// unrelated patch (seeds other_seed + i). A descriptor should change few bits for (a) and
// about half for (b).
struct NoiseAndOther {
  int noise = 0, other = 0;
};
inline NoiseAndOther MeanDistancesToNoisyAndOther(const Descriptor& d, std::uint64_t noise_seed,
                                                  std::uint64_t patch_seed,
                                                  std::uint64_t other_seed) {
  cv::RNG rng(noise_seed);
  constexpr int kPatches = 8;
  const int size = d.PatchSize();
  NoiseAndOther total;
  for (int i = 0; i < kPatches; ++i) {
    const cv::Mat patch = TexturedPatch(size, patch_seed + i);
    cv::Mat noise(size, size, CV_32F), f, noisy;
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
    patch.convertTo(f, CV_32F);
    cv::Mat(f + noise).convertTo(noisy, CV_8U);
    total.noise += Hamming(Describe(d, patch), Describe(d, noisy));
    total.other += Hamming(Describe(d, patch), Describe(d, TexturedPatch(size, other_seed + i)));
  }
  return {total.noise / kPatches, total.other / kPatches};
}

}  // namespace testing_util
}  // namespace openable
