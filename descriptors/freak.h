// FREAK, Fast Retina Keypoint, as the global descriptor of a square grey patch.
//
// Paper: A. Alahi, R. Ortiz and P. Vandergheynst, "FREAK: Fast Retina Keypoint", CVPR 2012.
// Written here from the paper, not from any code.
//
// Taken from the paper:
//  - a retinal sampling pattern: 43 receptive fields, one at the centre and 7 concentric rings
//    of 6, denser near the centre; fields overlap and their size grows exponentially with the
//    distance to the centre; neighbouring rings are rotated against each other;
//  - each field is smoothed before sampling; a binary test compares two smoothed fields,
//    T(P_a) = 1 when I(P_a^r1) - I(P_a^r2) > 0 and 0 otherwise;
//  - 512 of the 43 x 42 / 2 = 903 possible pairs are kept, chosen by the paper's greedy
//    decorrelation: order the pairs by how close the mean of their bit is to 0.5 over training
//    patches, keep a pair when it is little correlated with every pair already kept;
//  - 512 bits = 64 bytes, matched with the Hamming distance.
//
// Chosen here:
//  - geometry (the paper gives it as a figure, not as numbers), in units of R = S / 2, S the
//    patch side: ring k = 0 (innermost) .. 6 (outermost) has radius r_k = r_6 / 1.4^(6 - k),
//    fields of radius rho_k = 0.6 r_k (so two neighbours of a ring, 60 degrees apart at chord
//    r_k, overlap), r_6 = 1 / 1.6 so that the outermost fields touch the patch border
//    (r_6 + rho_6 = R); the centre field has radius rho_0. The pattern scales with the patch;
//  - field order and angles: fields 0-5 are ring 6, 6-11 ring 5, ..., 36-41 ring 0, 42 the
//    centre. Field j of a ring sits at angle 60 j degrees, plus 30 degrees on rings 5, 3, 1;
//    angle 0 points right (+x, increasing column) and 90 degrees up (decreasing row). The
//    patch centre is the continuous point (S/2, S/2), pixel (c, r) covering [c, c+1) x [r, r+1);
//  - smoothing: the mean over the pixels whose centres lie in the field's disc (the pixel under
//    the field centre when the disc holds none), summed from row spans of an integral image.
//    This stands in for the paper's Gaussian kernels; comparisons are exact in integers
//    (sum_a * n_b > sum_b * n_a);
//  - no orientation: the paper's orientation step (from 45 symmetric long pairs) is skipped,
//    because ABLE describes the whole image with no dominant orientation;
//  - the pair table: no training set ships with the toolbox, so the paper's selection was run
//    once offline here (bench/freak_pairs.cc, on whole frames of ../shared/datasets resized to
//    64 x 64, see freak.cc) and its result is the constant table FreakPairs();
//  - packing: test k (pair FreakPairs()[k]) goes to byte k / 8, bit k % 8 (least significant
//    bit first), as LDB and BRIEF.
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

// The 43 fields for an S x S patch, in field order (see above).
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
