// Figures of a run: the distance matrix drawn with the colour maps of the original OpenABLE,
// and PNG bytes of any image.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace openable {

// The 12 colour maps of the original OpenABLE (docs/output_formats.md). Pixel of a
// normalised distance s in [0, 1], as (blue, green, red) in [0, 1]; multiplied by 255 and
// rounded. Throws std::logic_error for a map outside 0-11.
cv::Vec3f ColorOf(float s, int map);
cv::Mat3b ColorizeMatrix(const cv::Mat1f& normalized, int map);

// Bytes of a PNG image (OpenCV's encoder).
std::string EncodePng(const cv::Mat& image);

}  // namespace openable
