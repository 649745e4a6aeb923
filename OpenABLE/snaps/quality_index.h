// SNAPS's inter-frame similarity (Sec. II-E, III-A): Wang & Bovik's universal image quality
// index (IEEE SPL 9(3), 2002) on thumbnails of the frames.
#pragma once

#include <opencv2/core.hpp>

namespace openable::snaps {

// Universal image quality index Q of two single-channel images of equal size (CV_8U, CV_32F or
// CV_64F, any mix): Eq. 4 and 5 of the SNAPS paper computed on every `window` x `window` block,
// the block sliding one pixel at a time horizontally and vertically, Q = mean of the local
// indices ((rows - B + 1) x (cols - B + 1) of them). In [-1, 1]; 1 only when the images are
// identical (up to the rule below). O(pixels): every local mean, variance and covariance
// comes from integral images, whatever B.
//
// Each local index is the product of a structure-contrast factor and a luminance factor,
//   Q = [2 s_xy / (s_x^2 + s_y^2)] * [2 x̄ ȳ / (x̄^2 + ȳ^2)],
// equal to Eq. 4 (the 1/(N-1) of Eq. 5 cancels). Zero denominators (not covered by Eq. 4):
//  - both windows constant (s_x^2 + s_y^2 = 0, within 1e-12 of the window's energy for float
//    input): the first factor is 1 (nothing of structure or contrast is lost), so two equal
//    constant windows give 1 and two different constant windows give the luminance factor;
//  - both means 0 (x̄^2 + ȳ^2 = 0): the luminance factor is 1 (equal means).
// One constant window against a non-constant one gives 0 (its covariance is 0).
// Throws std::invalid_argument on empty images, more than one channel, another depth, sizes
// that differ, window < 1 or a window larger than either side of the images.
double UniversalQualityIndex(const cv::Mat& x, const cv::Mat& y, int window);

// The thumbnail of a frame (Sec. III-A): `frame` resized by `scale` (0 < scale <= 1) with area
// interpolation (cv::INTER_AREA); each side is round(side * scale), at least 1 pixel. Keeps the
// type of `frame`. Throws std::invalid_argument on an empty frame or a scale outside (0, 1].
constexpr double kThumbnailScale = 1.0 / 6.0;
cv::Mat Thumbnail(const cv::Mat& frame, double scale = kThumbnailScale);

}  // namespace openable::snaps
