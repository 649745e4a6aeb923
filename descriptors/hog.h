// HOG (N. Dalal and B. Triggs, "Histograms of Oriented Gradients for Human Detection", CVPR
// 2005) as the global descriptor of the patch: OpenCV's cv::HOGDescriptor with the paper's
// default layout (8 x 8 cells, 16 x 16 blocks of stride 8, 9 unsigned bins, Gaussian window,
// L2-Hys clipped at 0.2) and one detection window equal to the whole S x S patch:
// ((S - 16) / 8 + 1)^2 blocks x 36 values, 1764 floats at S = 64. S must be a multiple of 8 and
// at least 16.
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
