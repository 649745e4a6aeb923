// LDB (X. Yang and K.-T. Cheng, ISMAR 2012 and IEEE T-PAMI 36(1):188-194, 2014) as the global
// descriptor of a square grey patch, as ABLE uses it (Arroyo et al., ITSC 2016, Eq. 1-4, and
// IV 2014), written from those descriptions: cell means and gradients on 2x2 to 5x5 grids, one
// test per cell pair and feature (1386 in canonical order), a subset kept, Hamming distance.
// Bits are not selected by AdaBoost as in T-PAMI (no training set ships) but by LdbSelection.
// Cells, test order and packing: docs/descriptors.md, "LDB".
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
