#include "descriptors/hog.h"

#include <opencv2/objdetect.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

constexpr int kCell = 8;
constexpr int kBlock = 16;
constexpr int kBlockStride = 8;
constexpr int kBins = 9;

cv::HOGDescriptor MakeHog(int patch_size) {
  return cv::HOGDescriptor(cv::Size(patch_size, patch_size), cv::Size(kBlock, kBlock),
                           cv::Size(kBlockStride, kBlockStride), cv::Size(kCell, kCell), kBins,
                           /*_derivAperture=*/1, /*_winSigma=*/-1.0 /* block width / 4 */,
                           cv::HOGDescriptor::L2Hys, /*_L2HysThreshold=*/0.2,
                           /*_gammaCorrection=*/false);
}

}  // namespace

HogDescriptor::HogDescriptor(const DescriptorOptions& options) : Descriptor(options), width_(0) {
  if (PatchSize() < kBlock || PatchSize() % kCell != 0) {
    throw InputError("Patch_size: " + std::to_string(PatchSize()) +
                     " does not suit HOG; expected a multiple of 8 that is at least 16");
  }
  width_ = static_cast<int>(MakeHog(PatchSize()).getDescriptorSize());
}

void HogDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  // cv::HOGDescriptor is a small parameter object; one per call keeps Describe thread-safe.
  const cv::HOGDescriptor hog = MakeHog(PatchSize());
  std::vector<float> values;
  // HOG reads pixels beyond a view's edges when the view is part of a larger image: compute on
  // a copy so the descriptor depends only on the patch.
  hog.compute(patch.isSubmatrix() ? patch.clone() : patch, values);
  if (static_cast<int>(values.size()) != width_) {
    throw std::logic_error("HOG: OpenCV returned " + std::to_string(values.size()) +
                           " values; expected " + std::to_string(width_));
  }
  cv::Mat(1, width_, CV_32FC1, values.data()).copyTo(row);
}

}  // namespace openable
