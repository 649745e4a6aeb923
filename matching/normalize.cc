#include "matching/normalize.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

namespace openable {

float LargestFiniteEntry(const cv::Mat1f& m) {
  if (m.empty()) return 0.0f;
  // One parallel pass for the check and the maximum.
  std::mutex mutex;
  float max_value = 0.0f;
  bool valid = true;
  cv::parallel_for_(cv::Range(0, m.rows), [&](const cv::Range& r) {
    float local = 0.0f;
    bool ok = true;
    for (int i = r.start; i < r.end; ++i) {
      const float* p = m.ptr<float>(i);
      for (int j = 0; j < m.cols; ++j) {
        ok &= p[j] >= 0.0f;  // false for NaN; +inf (a skipped sequence cell) is allowed
        if (p[j] <= std::numeric_limits<float>::max()) local = std::max(local, p[j]);
      }
    }
    std::lock_guard<std::mutex> lock(mutex);
    valid &= ok;
    max_value = std::max(max_value, local);
  });
  if (!valid) throw std::logic_error("NormalizeByMax: negative or NaN distance");
  return max_value;
}

void DivideByLargest(cv::Mat1f& m, float largest) {
  if (m.empty() || !(largest > 0.0f)) return;
  cv::parallel_for_(cv::Range(0, m.rows), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      float* p = m.ptr<float>(i);
      for (int j = 0; j < m.cols; ++j) p[j] /= largest;
    }
  });
}

float NormalizeByMax(cv::Mat1f& m) {
  const float max_value = LargestFiniteEntry(m);
  DivideByLargest(m, max_value);
  return max_value;
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
