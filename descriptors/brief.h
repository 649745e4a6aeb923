// BRIEF, Binary Robust Independent Elementary Features, as the global descriptor of a patch.
//
// Paper: M. Calonder, V. Lepetit, C. Strecha and P. Fua, "BRIEF: Binary Robust Independent
// Elementary Features", ECCV 2010 (and the longer T-PAMI 34(7), 2012 version, "BRIEF:
// Computing a Local Binary Descriptor Very Fast"). Written here from the papers, not from any
// code.
//
// Taken from the papers:
//  - the descriptor is n_d = 256 binary tests (32 bytes) on a smoothed S x S patch; test
//    tau(p; x, y) = 1 when p(x) < p(y) and 0 otherwise, where p(.) is the smoothed intensity;
//  - the test locations are the paper's G II: x and y drawn i.i.d. from an isotropic Gaussian
//    centred on the keypoint with sigma^2 = S^2 / 25 (sigma = S / 5), drawn once and reused
//    for every patch;
//  - the descriptor is matched with the Hamming distance.
//
// Chosen here:
//  - smoothing: box smoothing through an integral image, as in the T-PAMI version, rather than
//    the ECCV paper's 9 x 9 Gaussian of sigma 2. Only the 512 test pixels need a smoothed
//    value, so each costs four look-ups into exact integer sums, whatever the patch size; the
//    result is bit-exact on every machine (no floating-point rounding in the comparisons); and
//    a window that meets the patch border simply shrinks to the pixels inside (the mean over
//    them), which gives a clear meaning to tests near the border of a whole-image patch. The
//    box has side 2h + 1 with h = max(1, round(4 S / 48)): the paper's 9 x 9 extent at its
//    S = 48, scaled with the patch (11 x 11 at S = 64, 3 x 3 at S = 16);
//  - smoothed value p(x) = mean of the box around x clipped to the patch; the comparison
//    p(x) < p(y) is done exactly as sum_x * n_y < sum_y * n_x in 64-bit integers;
//  - the pattern: std::mt19937 seeded with kBriefPatternSeed ("BRIE" in ASCII); each standard
//    normal pair comes from two raw 32-bit outputs a, b by Box-Muller in double:
//    u1 = (a + 0.5) / 2^32, u2 = (b + 0.5) / 2^32, r = sqrt(-2 ln u1), z0 = r cos(2 pi u2),
//    z1 = r sin(2 pi u2) (std::normal_distribution is implementation-defined and not used).
//    Test k uses pairs 2k and 2k + 1: x = (z0, z1) of pair 2k, y = (z0, z1) of pair 2k + 1
//    (column offset first, then row offset), in units of sigma;
//  - scaling and clipping: the keypoint is the patch centre, the continuous point (S/2, S/2)
//    where pixel (c, r) covers [c, c + 1) x [r, r + 1); a unit offset z becomes pixel
//    floor(S / 2 + z S / 5), clipped to [0, S - 1] (about 2.5% of the points fall outside the
//    patch and land on its border). The unit pattern is the same for every S;
//  - no orientation and no scale estimation (ABLE describes the whole image resized to the
//    patch). Tests whose two points fall on the same pixel (rare, more so at small S) are kept:
//    they are always 0, as in the paper's pattern;
//  - packing: test k goes to byte k / 8, bit k % 8 (least significant bit first), as LDB.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

inline constexpr int kBriefTests = 256;
// Seed of the std::mt19937 that draws the BRIEF pattern: 0x42524945, "BRIE" in ASCII.
inline constexpr std::uint32_t kBriefPatternSeed = 0x42524945u;

// One BRIEF test in unit offsets from the centre (standard normal deviates, multiply by S / 5
// for pixels): compare the smoothed intensity at (x_col, x_row) with that at (y_col, y_row).
struct BriefUnitTest {
  double x_col, x_row, y_col, y_row;
};

// The 256 tests of the unit pattern, drawn as described above.
const std::array<BriefUnitTest, kBriefTests>& BriefUnitPattern();

// A test in pixels of an S x S patch, clipped to the patch.
struct BriefPixelTest {
  int x_col, x_row, y_col, y_row;
};

class BriefDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size when options.patch_size < 16.
  explicit BriefDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "BRIEF"; }
  int Width() const override { return kBriefTests / 8; }
  DescriptorKind Kind() const override { return DescriptorKind::kBinary; }

  // Half-side h of the smoothing box (side 2h + 1) at this patch size.
  int BoxHalfSide() const { return half_; }
  // The 256 tests in pixels, in descriptor bit order.
  const std::vector<BriefPixelTest>& PixelTests() const { return tests_; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  int half_;
  std::vector<BriefPixelTest> tests_;
};

}  // namespace openable
