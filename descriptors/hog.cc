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

std::string Shape(const cv::Mat& m) {
  return std::to_string(m.rows) + " x " + std::to_string(m.cols) + " " + cv::typeToString(m.type());
}

}  // namespace

HogDescriptor::HogDescriptor(const DescriptorOptions& options)
    : patch_size_(options.patch_size), width_(0) {
  if (patch_size_ < kBlock || patch_size_ % kCell != 0) {
    throw InputError("Patch_size: " + std::to_string(patch_size_) +
                     " does not suit HOG; expected a multiple of 8 that is at least 16");
  }
  width_ = static_cast<int>(MakeHog(patch_size_).getDescriptorSize());
}

void HogDescriptor::Describe(const cv::Mat& patch, cv::Mat row) const {
  if (patch.type() != CV_8UC1 || patch.rows != patch_size_ || patch.cols != patch_size_) {
    throw std::logic_error("HOG: expected a " + std::to_string(patch_size_) + " x " +
                           std::to_string(patch_size_) + " CV_8UC1 patch, got " + Shape(patch));
  }
  if (row.type() != CV_32FC1 || row.rows != 1 || row.cols != width_) {
    throw std::logic_error("HOG: expected a 1 x " + std::to_string(width_) + " CV_32FC1 row, got " +
                           Shape(row));
  }
  // cv::HOGDescriptor is a small parameter object; one per call keeps Describe thread-safe.
  const cv::HOGDescriptor hog = MakeHog(patch_size_);
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
