// BRIEF (M. Calonder, V. Lepetit, C. Strecha and P. Fua, "BRIEF: Binary Robust Independent
// Elementary Features", ECCV 2010; T-PAMI 34(7), 2012) as the global descriptor of a patch,
// written from the papers: 256 tests on a smoothed S x S patch at the paper's G II locations,
// matched by Hamming distance. Smoothing is a box from an integral image (the T-PAMI variant)
// rather than a Gaussian: exact integer sums give the same bits on every machine. Pattern
// recipe, box size, clipping and bit order: docs/descriptors.md, "BRIEF".
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

// The 256 tests of the unit pattern (docs/descriptors.md, "BRIEF": seeded Box-Muller).
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
