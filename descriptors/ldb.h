// LDB, Local Difference Binary, as the global descriptor of a square grey patch.
//
// Papers: X. Yang and K.-T. Cheng, "LDB: An Ultra-Fast Feature for Scalable Augmented Reality
// on Mobile Devices", ISMAR 2012, and "Local Difference Binary for Ultrafast and Distinctive
// Feature Description", IEEE T-PAMI 36(1):188-194, 2014; as ABLE uses it (Arroyo et al.,
// ITSC 2016, Eq. 1-4, and IV 2014: 64 x 64 patch, 32-byte strings). Written here from those
// descriptions, not from any code.
//
// Taken from the papers:
//  - the patch is divided into n x n grids of cells at several levels (multiple gridding);
//  - each cell gives three features from an integral image: the average intensity I_avg and the
//    horizontal and vertical gradients G_x, G_y of the cell (OpenABLE Eq. 2);
//  - every pair of cells of a level gives one binary test per feature, tau = 1 when
//    f(i) < f(j) and 0 otherwise (OpenABLE Eq. 1); the tests are packed into a bit string
//    (Eq. 3) matched with the Hamming distance (Eq. 4);
//  - a subset of the tests is kept (the papers select bits; ABLE keeps 256 bits = 32 bytes).
//
// Chosen here (the papers leave these open or rely on a detector this toolbox does not use):
//  - levels n = 2, 3, 4, 5, all four; cell (r, c) of level n covers rows
//    [floor(r S / n), floor((r + 1) S / n)) and the same for columns (S = patch side);
//  - G_x = mean of the right half minus mean of the left half, split at the integer column
//    midpoint (x0 + x1) / 2; G_y likewise with the bottom and top halves. Means rather than sums,
//    so that cells of unequal size compare fairly. Features are computed in double precision;
//  - the keypoint is the patch centre, with no orientation and no scale estimation, and no
//    smoothing beyond the cell averaging (ABLE describes a patch resized from the whole image);
//  - canonical test order: level 2, 3, 4, 5; within a level the cell pairs (i, j), i < j, in
//    lexicographic order of row-major cell indices; within a pair I_avg, G_x, G_y. This gives
//    3 x (6 + 36 + 120 + 300) = 1386 tests;
//  - bit selection is not learnt (the T-PAMI paper selects bits with AdaBoost on training
//    patches): kRandom keeps a fixed pseudo-random subset, kCoarseFirst the first tests of the
//    canonical order (see LdbSelection);
//  - packing: selected test k goes to byte k / 8, bit k % 8 (least significant bit first);
//    the unused high bits of the last byte are 0.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

// Number of binary tests over the four grid levels 2, 3, 4, 5 (all cell pairs, 3 features).
inline constexpr int kLdbTotalTests = 1386;

// Seed of the std::mt19937 that drives the kRandom selection: 0x4C4442, the ASCII codes of
// "LDB". Changing it changes every LDB descriptor written with fewer than 1386 bits.
inline constexpr std::uint32_t kLdbSelectionSeed = 0x4C4442u;

// How LDB keeps `bits` of its 1386 tests when bits < 1386 (with 1386 both keep every test in
// canonical order).
enum class LdbSelection {
  // The first `bits` entries of a Fisher-Yates shuffle of the test indices 0..1385: for
  // i = 1385 down to 1, j = (raw 32-bit output of std::mt19937(kLdbSelectionSeed)) % (i + 1),
  // swap entries i and j. Only raw mt19937 outputs are used, so the selection is the same with
  // every standard library. Mixes all levels and features.
  kRandom,
  // The first `bits` tests of the canonical order: coarse levels first.
  kCoarseFirst,
};

// Canonical indices of the tests kept for `bits` (1..1386) under `selection`, in descriptor bit
// order: bit k of a descriptor is test LdbSelectedTests(bits, selection)[k]. Throws
// std::logic_error when bits is outside [1, 1386].
std::vector<int> LdbSelectedTests(int bits, LdbSelection selection);

// LDB over a patch_size x patch_size CV_8UC1 patch, options.ldb_bits bits, Width() =
// ceil(ldb_bits / 8) bytes.
class LdbDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size (< 16) or Ldb_bits (outside [1, 1386]).
  explicit LdbDescriptor(const DescriptorOptions& options,
                         LdbSelection selection = LdbSelection::kRandom);

  std::string Name() const override { return "LDB"; }
  int Width() const override { return (bits_ + 7) / 8; }
  DescriptorKind Kind() const override { return DescriptorKind::kBinary; }

  // Bits kept (options.ldb_bits).
  int Bits() const { return bits_; }
  LdbSelection Selection() const { return selection_; }
  // LdbSelectedTests(Bits(), Selection()).
  const std::vector<int>& SelectedTests() const { return selected_; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  // A cell, in patch pixels: rows [y0, y1), columns [x0, x1); halves split at xm and ym.
  struct Cell {
    int y0, y1, x0, x1, xm, ym;
  };
  // One selected test: compare feature a with feature b (indices into the feature array,
  // 3 * cell + feature).
  struct Test {
    std::uint16_t a, b;
  };

  int bits_;
  LdbSelection selection_;
  std::vector<int> selected_;
  std::vector<Cell> cells_;  // levels 2..5 in order, row-major within a level
  std::vector<Test> tests_;  // the selected tests, in descriptor bit order
};

}  // namespace openable
