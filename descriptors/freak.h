// FREAK (A. Alahi, R. Ortiz and P. Vandergheynst, "FREAK: Fast Retina Keypoint", CVPR 2012)
// as the global descriptor of a square grey patch, written from the paper: 43 overlapping
// receptive fields in 7 rings of 6 and a centre, 512 tests between field means, Hamming distance.
// The paper gives the geometry only as a figure, so ring and field radii are chosen here; fields
// are disc means from an integral image (exact integer comparisons) instead of Gaussians; no
// orientation step, as ABLE has no dominant orientation. The pair table was selected offline by
// bench/freak_pairs.cc (no training set ships). docs/descriptors.md, "FREAK".
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

inline constexpr int kFreakFields = 43;
inline constexpr int kFreakRings = 7;
inline constexpr int kFreakAllPairs = kFreakFields * (kFreakFields - 1) / 2;  // 903
inline constexpr int kFreakBits = 512;

// One receptive field in continuous patch coordinates (pixels).
struct FreakField {
  double x, y;    // centre: column, row
  double radius;  // disc radius
  int ring;       // 0 (innermost) .. 6 (outermost); -1 for the centre field
};

// The 43 fields for an S x S patch, in field order: 0-5 ring 6 (outermost), 6-11 ring 5, ...,
// 36-41 ring 0, 42 the centre. Field j of a ring sits at 60 j degrees (plus 30 on rings 5, 3,
// 1), 0 pointing right and 90 up, around the continuous point (S/2, S/2).
std::vector<FreakField> FreakFields(int patch_size);

// The 512 pairs (i, j), i < j, in descriptor bit order: bit k is 1 when the mean of field
// FreakPairs()[k][0] is greater than that of field FreakPairs()[k][1].
const std::array<std::array<std::uint8_t, 2>, kFreakBits>& FreakPairs();

class FreakDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size when options.patch_size < 16.
  explicit FreakDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "FREAK"; }
  int Width() const override { return kFreakBits / 8; }
  DescriptorKind Kind() const override { return DescriptorKind::kBinary; }

  // All 903 tests of `patch` (same checks as Describe), one 0/1 value each, pairs (i, j),
  // i < j, in lexicographic order. Used to select the pairs (bench/freak_pairs.cc).
  std::vector<std::uint8_t> AllPairBits(const cv::Mat& patch) const;
  // Number of pixels averaged by each field.
  const std::vector<int>& FieldPixelCounts() const { return counts_; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  struct Span {
    int row, x0, x1;  // pixels [x0, x1) of row `row`
  };
  // Sum of each field's pixels.
  void FieldSums(const cv::Mat& patch, std::int64_t* sums) const;

  std::vector<std::vector<Span>> spans_;  // per field
  std::vector<int> counts_;               // per field
};

}  // namespace openable
