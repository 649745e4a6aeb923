#include "matching/sequence.h"

#include <algorithm>
#include <stdexcept>

namespace openable {
namespace {

// is_start[x] is true when frame x begins a traversal.
std::vector<char> StartFlags(const std::vector<int>& starts, int n, const char* what) {
  std::vector<char> flags(static_cast<size_t>(n) + 1, 0);
  if (n > 0) flags[0] = 1;
  int prev = -1;
  for (int s : starts) {
    if (s <= prev || s < 0 || (prev < 0 && s != 0))
      throw std::logic_error(std::string("SequenceDistances: ") + what +
                             " starts must increase from 0");
    if (s < n) flags[s] = 1;
    prev = s;
  }
  return flags;
}

}  // namespace

cv::Mat1f SequenceDistances(const cv::Mat1f& d, int sequence_length,
                            const std::vector<int>& row_starts,
                            const std::vector<int>& col_starts) {
  if (sequence_length < 1) throw std::logic_error("SequenceDistances: sequence length < 1");
  const int n = d.rows, m = d.cols;
  const std::vector<char> row_start = StartFlags(row_starts, n, "row");
  const std::vector<char> col_start = StartFlags(col_starts, m, "column");
  cv::Mat1f out(n, m);
  if (sequence_length == 1) {
    d.copyTo(out);
    return out;
  }
  const int L = sequence_length;
  // Walk every diagonal from its top-left end. The window holds the last `count` terms of
  // the current run; a run restarts where the row or the column frame begins a traversal.
  // Sums are kept in double so that long diagonals do not accumulate float rounding.
  auto walk = [&](int i, int j) {
    double sum = 0.0;
    int count = 0;
    for (; i < n && j < m; ++i, ++j) {
      if (row_start[i] || col_start[j]) {
        sum = 0.0;
        count = 0;
      }
      sum += d(i, j);
      if (count == L) {
        sum -= d(i - L, j - L);
      } else {
        ++count;
      }
      out(i, j) = static_cast<float>(count == L ? sum : sum * L / count);
    }
  };
  for (int j = 0; j < m; ++j) walk(0, j);
  for (int i = 1; i < n; ++i) walk(i, 0);
  return out;
}

}  // namespace openable
