#include "OpenABLE/snaps/quality_index.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace openable::snaps {
namespace {

cv::Mat1d ToDouble(const cv::Mat& m, const char* name) {
  if (m.empty())
    throw std::invalid_argument(std::string("UniversalQualityIndex: ") + name + " is empty");
  if (m.channels() != 1 || (m.depth() != CV_8U && m.depth() != CV_32F && m.depth() != CV_64F))
    throw std::invalid_argument(std::string("UniversalQualityIndex: ") + name +
                                " must be one channel of CV_8U, CV_32F or CV_64F");
  cv::Mat1d out;
  m.convertTo(out, CV_64F);
  return out;
}

// Sum of the B x B window with top-left corner (r, c) from an integral image.
inline double Box(const cv::Mat1d& integral, int r, int c, int b) {
  return integral(r + b, c + b) - integral(r, c + b) - integral(r + b, c) + integral(r, c);
}

}  // namespace

double UniversalQualityIndex(const cv::Mat& x, const cv::Mat& y, int window) {
  const cv::Mat1d a = ToDouble(x, "x"), b = ToDouble(y, "y");
  if (a.size() != b.size())
    throw std::invalid_argument("UniversalQualityIndex: sizes differ (" + std::to_string(a.cols) +
                                "x" + std::to_string(a.rows) + " and " + std::to_string(b.cols) +
                                "x" + std::to_string(b.rows) + ")");
  if (window < 1 || window > a.rows || window > a.cols)
    throw std::invalid_argument("UniversalQualityIndex: window " + std::to_string(window) +
                                " must be in [1, min(rows, cols)] for a " + std::to_string(a.cols) +
                                "x" + std::to_string(a.rows) + " image");
  cv::Mat1d sx, sxx, sy, syy, sxy;
  cv::integral(a, sx, sxx, CV_64F, CV_64F);
  cv::integral(b, sy, syy, CV_64F, CV_64F);
  cv::integral(a.mul(b), sxy, CV_64F);

  const double n = static_cast<double>(window) * window;
  const int rows = a.rows - window + 1, cols = a.cols - window + 1;
  double total = 0;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x1 = Box(sx, r, c, window), y1 = Box(sy, r, c, window);
      const double x2 = Box(sxx, r, c, window), y2 = Box(syy, r, c, window);
      const double xy = Box(sxy, r, c, window);
      // N (N - 1) times the variances and the covariance (exact integers for 8-bit input).
      const double vx = std::max(0.0, n * x2 - x1 * x1), vy = std::max(0.0, n * y2 - y1 * y1);
      const double cxy = n * xy - x1 * y1;
      const double v = vx + vy;
      const double structure = v <= 1e-12 * n * (x2 + y2) ? 1.0 : 2.0 * cxy / v;
      const double m = x1 * x1 + y1 * y1;
      const double luminance = m == 0 ? 1.0 : 2.0 * x1 * y1 / m;
      total += structure * luminance;
    }
  }
  return total / (static_cast<double>(rows) * cols);
}

cv::Mat Thumbnail(const cv::Mat& frame, double scale) {
  if (frame.empty()) throw std::invalid_argument("Thumbnail: empty frame");
  if (!(scale > 0 && scale <= 1))
    throw std::invalid_argument("Thumbnail: scale " + std::to_string(scale) + " outside (0, 1]");
  const int w = std::max(1, static_cast<int>(std::lround(frame.cols * scale)));
  const int h = std::max(1, static_cast<int>(std::lround(frame.rows * scale)));
  cv::Mat out;
  cv::resize(frame, out, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  return out;
}

}  // namespace openable::snaps
