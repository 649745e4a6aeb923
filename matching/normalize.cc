#include "matching/normalize.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace openable {

float NormalizeByMax(cv::Mat1f& m) {
  if (m.empty()) return 0.0f;
  if (!cv::checkRange(m, /*quiet=*/true, nullptr, 0.0, std::numeric_limits<double>::max()))
    throw std::logic_error("NormalizeByMax: negative or non-finite distance");
  double max_value = 0.0;
  cv::minMaxLoc(m, nullptr, &max_value);
  if (max_value > 0.0) m /= max_value;
  return static_cast<float>(max_value);
}

cv::Mat1b ThresholdMatrix(const cv::Mat1f& normalized, float theta) {
  cv::Mat1b out(normalized.size());
  for (int i = 0; i < normalized.rows; ++i) {
    const float* in = normalized.ptr<float>(i);
    std::uint8_t* o = out.ptr<std::uint8_t>(i);
    for (int j = 0; j < normalized.cols; ++j) o[j] = in[j] < theta ? 0 : 1;
  }
  return out;
}

}  // namespace openable
