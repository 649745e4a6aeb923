#include "OpenABLE/reports/figures.h"

#include <cmath>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

#include "OpenABLE/io/image_codec.h"

namespace openable {

cv::Vec3f ColorOf(float s, int map) {
  // (blue, green, red), as the original OpenABLE's table (docs/output_formats.md).
  switch (map) {
    case 0:
      return {s, s, s};
    case 1:
      return {0, 0, s};
    case 2:
      return {0, s, 0};
    case 3:
      return {s, 0, 0};
    case 4:
      return {1 - s, 1 - s, s};
    case 5:
      return {1 - s, s, 1 - s};
    case 6:
      return {s, 1 - s, 1 - s};
    case 7:
      return {0, s, 1};
    case 8:
      return {1, 1 - s, s};
    case 9:
      return {0.4980f * s, 0.7804f * s, s};
    case 10:
      return {1 - s, s, 1};
    case 11:
      return {0, 0.5f * s + 0.5f, s};
    default:
      throw std::logic_error("ColorOf: colour map outside 0-11");
  }
}

cv::Mat3b ColorizeMatrix(const cv::Mat1f& normalized, int map) {
  // Every map is affine in s per channel: c = b + a s, with b = ColorOf(0), a = ColorOf(1) - b,
  // which gives the same floats as ColorOf (the slopes are 0, +-1, 0.4980 or 0.5).
  const cv::Vec3f b = ColorOf(0.f, map);  // also validates the map
  const cv::Vec3f a = ColorOf(1.f, map) - b;
  cv::Mat3b out(normalized.size());
  cv::parallel_for_(cv::Range(0, normalized.rows), [&](const cv::Range& rows) {
    for (int i = rows.start; i < rows.end; ++i) {
      const float* in = normalized.ptr<float>(i);
      std::uint8_t* o = out.ptr<std::uint8_t>(i);
      for (int j = 0; j < normalized.cols; ++j) {
        const float v = std::min(1.f, std::max(0.f, in[j]));
        for (int k = 0; k < 3; ++k)
          o[3 * j + k] = cv::saturate_cast<std::uint8_t>((b[k] + a[k] * v) * 255.f);
      }
    }
  });
  return out;
}

std::string EncodePng(const cv::Mat& image) { return EncodePngFile(image); }

}  // namespace openable
