// HOG, histograms of oriented gradients, as the global descriptor of the patch.
//
// Paper: N. Dalal and B. Triggs, "Histograms of Oriented Gradients for Human Detection",
// CVPR 2005. The descriptor is OpenCV's cv::HOGDescriptor, with the paper's default layout:
// 8 x 8-pixel cells, 2 x 2-cell blocks (16 x 16 pixels) overlapping by half (stride 8), 9
// unsigned orientation bins over 0-180 degrees, Gaussian block window (sigma 4 = block width / 4),
// L2-Hys block normalisation clipped at 0.2, no gamma correction.
//
// Chosen here: one detection window equal to the whole S x S patch (no padding), so the
// descriptor has ((S - 16) / 8 + 1)^2 blocks x 36 values: 1764 floats for S = 64, 324 for S = 32.
// S must be a multiple of 8 (whole cells) and at least 16 (one block).
#pragma once

#include <string>

#include "descriptors/descriptor.h"

namespace openable {

class HogDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size when options.patch_size is below 16 or not a multiple
  // of 8.
  explicit HogDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "HOG"; }
  int Width() const override { return width_; }
  DescriptorKind Kind() const override { return DescriptorKind::kFloat; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  int width_;
};

}  // namespace openable
