// SAD, the image description of SeqSLAM: a small patch-normalised thumbnail of the frame,
// compared by the sum of absolute differences.
//
// Paper: M. J. Milford and G. F. Wyeth, "SeqSLAM: Visual Route-Based Navigation for Sunny Summer
// Days and Stormy Winter Nights", ICRA 2012 (and N. Suenderhauf et al.'s OpenSeqSLAM, which
// fixed the settings most papers use: 64 x 32 pixel frames, patches of 8 pixels).
//
// Chosen here:
//  - The thumbnail is Patch_size pixels wide and Patch_size / 2 high (64 x 32 by default: the
//    2:1 frame of SeqSLAM's Nordland runs), whatever the frame's aspect: the square patch the
//    frame describer hands over (the frame resized to Patch_size x Patch_size, or a grid cell)
//    is resized to it by pixel-area averaging.
//  - It is cut into Sad_patch x Sad_patch squares from the top left (the last row and column of
//    squares are smaller when Sad_patch does not divide the sides); each square is normalised to
//    zero mean and unit standard deviation (population), a uniform square becomes 0.
//  - Each normalised value z is stored as one byte, clamp(round(128 + 32 z), 0, 255): steps of
//    1/32 of a standard deviation, saturating at 4 standard deviations. Bytes keep the rows
//    four times smaller than floats and let the distance run on the CPU's sum-of-absolute-
//    differences instruction; the rounding changes a distance by at most half a step per
//    element.
//  - The row is the thumbnail in row-major order; the distance of two rows is the sum of the
//    absolute differences of their bytes (L1): 32 x Width() times SeqSLAM's mean absolute
//    difference of the normalised values, a constant factor that Eq. 5's normalisation removes.
#pragma once

#include <string>

#include "descriptors/descriptor.h"

namespace openable {

class SadDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Sad_patch when it exceeds the thumbnail's height (Patch_size / 2).
  explicit SadDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "SAD"; }
  int Width() const override { return width_ * height_; }
  DescriptorKind Kind() const override { return DescriptorKind::kBytes; }

  // The thumbnail's size: Patch_size x Patch_size / 2 (width x height).
  cv::Size ThumbnailSize() const { return {width_, height_}; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  int width_, height_, sad_patch_;
};

}  // namespace openable
