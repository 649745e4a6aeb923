#include "matching/contrast.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/threading.h"

namespace openable {

void ContrastOptions::Check() const { CheckIntRange("Contrast_window", window, 1, 100000); }

float EnhanceContrastUnshifted(cv::Mat1f& d, int window, const std::vector<int>& col_starts,
                               int threads) {
  if (window < 1) throw std::logic_error("EnhanceContrast: window below 1");
  const int n = d.rows, m = d.cols;
  if (n == 0 || m == 0) return std::numeric_limits<float>::infinity();
  // The traversal of each column: [first, end).
  std::vector<int> first(static_cast<size_t>(m)), end(static_cast<size_t>(m));
  std::vector<int> starts = col_starts.empty() ? std::vector<int>{0} : col_starts;
  starts.push_back(m);
  for (size_t t = 0; t + 1 < starts.size(); ++t)
    for (int j = std::min(starts[t], m); j < std::min(starts[t + 1], m); ++j)
      first[static_cast<size_t>(j)] = starts[t], end[static_cast<size_t>(j)] = starts[t + 1];

  std::mutex mutex;
  float smallest = std::numeric_limits<float>::infinity();
  ParallelFor(n, threads, [&](int i) {
    float* row = d.ptr<float>(i);
    // Prefix sums of the finite values, their squares and their count (double: a row of
    // 100,000 distances keeps its precision).
    std::vector<double> s(static_cast<size_t>(m) + 1, 0.0), s2(s.size(), 0.0);
    std::vector<int> count(s.size(), 0);
    for (int j = 0; j < m; ++j) {
      const bool finite = std::isfinite(row[j]);
      const double v = finite ? row[j] : 0.0;
      s[j + 1] = s[j] + v;
      s2[j + 1] = s2[j] + v * v;
      count[j + 1] = count[j] + (finite ? 1 : 0);
    }
    float local = std::numeric_limits<float>::infinity();
    for (int j = 0; j < m; ++j) {
      if (!std::isfinite(row[j])) continue;
      const int a = std::max(first[j], j - window), b = std::min(end[j], j + window + 1);
      const int c = count[b] - count[a];
      const double mean = (s[b] - s[a]) / c;
      const double var = std::max(0.0, (s2[b] - s2[a]) / c - mean * mean);
      const double sd = std::sqrt(var);
      // Rounding leaves a tiny variance where every value is equal: treat as equal.
      const float v =
          sd > 1e-9 * (std::fabs(mean) + 1.0) ? static_cast<float>((row[j] - mean) / sd) : 0.0f;
      row[j] = v;
      local = std::min(local, v);
    }
    std::lock_guard<std::mutex> lock(mutex);
    smallest = std::min(smallest, local);
  });
  return smallest;
}

void EnhanceContrast(cv::Mat1f& d, int window, const std::vector<int>& col_starts, int threads) {
  const float smallest = EnhanceContrastUnshifted(d, window, col_starts, threads);
  const int n = d.rows, m = d.cols;
  if (!std::isfinite(smallest) || smallest == 0.0f) return;
  ParallelFor(n, threads, [&](int i) {
    float* row = d.ptr<float>(i);
    for (int j = 0; j < m; ++j)
      if (std::isfinite(row[j])) row[j] -= smallest;
  });
}

}  // namespace openable
