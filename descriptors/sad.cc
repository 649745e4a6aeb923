#include "descriptors/sad.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <string>

#include "OpenABLE/base/error.h"

namespace openable {

SadDescriptor::SadDescriptor(const DescriptorOptions& options)
    : Descriptor(options),
      width_(options.patch_size),
      height_(options.patch_size / 2),
      sad_patch_(options.sad_patch) {
  if (sad_patch_ > height_) {
    throw InputError("Sad_patch: " + std::to_string(sad_patch_) +
                     " is larger than the SAD thumbnail's height (Patch_size " +
                     std::to_string(options.patch_size) + " / 2 = " + std::to_string(height_) +
                     "); expected at most " + std::to_string(height_));
  }
}

void SadDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  cv::Mat thumbnail;
  cv::resize(patch, thumbnail, cv::Size(width_, height_), 0, 0, cv::INTER_AREA);
  std::uint8_t* out = row.ptr<std::uint8_t>(0);
  for (int y0 = 0; y0 < height_; y0 += sad_patch_) {
    for (int x0 = 0; x0 < width_; x0 += sad_patch_) {
      const cv::Rect square(x0, y0, std::min(sad_patch_, width_ - x0),
                            std::min(sad_patch_, height_ - y0));
      cv::Scalar mean, deviation;
      cv::meanStdDev(thumbnail(square), mean, deviation);
      const double m = mean[0], s = deviation[0];
      for (int y = square.y; y < square.y + square.height; ++y) {
        const std::uint8_t* in = thumbnail.ptr<std::uint8_t>(y);
        for (int x = square.x; x < square.x + square.width; ++x) {
          // A uniform square (s = 0) has no contrast to normalise: it becomes z = 0.
          const double z = s > 0 ? (in[x] - m) / s : 0.0;
          out[y * width_ + x] =
              static_cast<std::uint8_t>(std::clamp(std::lround(128.0 + 32.0 * z), 0L, 255L));
        }
      }
    }
  }
}

}  // namespace openable
