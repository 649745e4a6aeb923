// Helpers shared by the descriptor tests: fixed-seed test patches and one-row description.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

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

// Bit k of a binary descriptor row: bit k % 8 of byte k / 8.
inline int Bit(const cv::Mat& row, int k) {
  return (row.at<std::uint8_t>(0, k / 8) >> (k % 8)) & 1;
}

// A 64 x 64 patch, columns 0-31 at 200 and 32-63 at 50: a region wholly on one side of column 32
// has that side's mean.
inline cv::Mat BrightLeftDarkRightPatch() {
  cv::Mat patch(64, 64, CV_8UC1, cv::Scalar(50));
  patch(cv::Rect(0, 0, 32, 64)).setTo(200);
  return patch;
}

// Where a test's region lies in BrightLeftDarkRightPatch().
enum class Half { kLeft, kRight, kStraddles };

struct DecidedBits {
  int decided = 0, ones = 0;
};

// The bits of `row` (k < bits) whose two regions, halves(k), each lie wholly in one half are
// decided by the patch: expects such a bit to be 1 exactly when halves(k) is `one`, and counts
// the decided bits and the ones among them.
template <typename Halves>
DecidedBits ExpectBitsDecidedByHalves(const cv::Mat& row, int bits, Halves halves,
                                      std::pair<Half, Half> one) {
  DecidedBits count;
  for (int k = 0; k < bits; ++k) {
    const std::pair<Half, Half> h = halves(k);
    if (h.first == Half::kStraddles || h.second == Half::kStraddles) continue;
    ++count.decided;
    const int expected = h == one ? 1 : 0;
    EXPECT_EQ(Bit(row, k), expected) << "bit " << k;
    count.ones += expected;
  }
  return count;
}

// Expects bit k of `row` to be expected[k] for every k of `expected`; returns the number of ones
// in `expected`.
inline int ExpectBitsAre(const cv::Mat& row, const std::vector<int>& expected) {
  int ones = 0;
  for (int k = 0; k < static_cast<int>(expected.size()); ++k) {
    EXPECT_EQ(Bit(row, k), expected[k]) << "bit " << k;
    ones += expected[k];
  }
  return ones;
}

// Bounds on mean Hamming distances: to a noisy copy of a patch below `noise_below`, to an
// unrelated patch strictly between `other_above` and `other_below`.
struct DistanceBounds {
  int noise_below, other_above, other_below;
};

// Expects the mean Hamming distances over 8 textured patches (seeds patch_seed + i) between each
// patch and (a) itself with Gaussian noise of sigma 3 grey levels (drawn from noise_seed) and
// (b) an unrelated patch (seeds other_seed + i) to lie within `bounds`. A descriptor should
// change few bits for (a) and about half for (b).
inline void ExpectNoisyCloseAndOtherFar(const Descriptor& d, std::uint64_t noise_seed,
                                        std::uint64_t patch_seed, std::uint64_t other_seed,
                                        const DistanceBounds& bounds) {
  cv::RNG rng(noise_seed);
  constexpr int kPatches = 8;
  const int size = d.PatchSize();
  int noise_total = 0, other_total = 0;
  for (int i = 0; i < kPatches; ++i) {
    const cv::Mat patch = TexturedPatch(size, patch_seed + i);
    cv::Mat noise(size, size, CV_32F), f, noisy;
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
    patch.convertTo(f, CV_32F);
    cv::Mat(f + noise).convertTo(noisy, CV_8U);
    noise_total += Hamming(Describe(d, patch), Describe(d, noisy));
    other_total += Hamming(Describe(d, patch), Describe(d, TexturedPatch(size, other_seed + i)));
  }
  const int noise_mean = noise_total / kPatches, other_mean = other_total / kPatches;
  EXPECT_LT(noise_mean, bounds.noise_below);
  EXPECT_GT(other_mean, bounds.other_above);
  EXPECT_LT(other_mean, bounds.other_below);
}

}  // namespace testing_util
}  // namespace openable
