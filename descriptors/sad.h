// SAD, the image description of SeqSLAM (M. J. Milford and G. F. Wyeth, "SeqSLAM: Visual
// Route-Based Navigation for Sunny Summer Days and Stormy Winter Nights", ICRA 2012, with the
// settings of N. Suenderhauf et al.'s OpenSeqSLAM): a Patch_size x Patch_size / 2 thumbnail,
// normalised in Sad_patch squares, one byte per value (clamp(round(128 + 32 z), 0, 255)) so
// that rows are four times smaller than floats and the L1 distance runs on the CPU's
// sum-of-absolute-differences instruction. docs/descriptors.md, "SAD (SeqSLAM)".
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
