#include "matching/panorama.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "matching/large_matrix.h"

namespace openable {
namespace {

// out = min(out, d), cell by cell, in place.
void MinInto(cv::Mat1f& out, const cv::Mat1f& d) {
  cv::Mat o = out;
  cv::min(o, cv::Mat(d), o);
}

}  // namespace

cv::Mat1f PanoramaDistances(const cv::Mat& rows, int strips, PanoramaMatching mode, int threads,
                            const PairProgress& progress, std::optional<Metric> metric_given) {
  return PanoramaDistances(rows, cv::Mat(), strips, mode, threads, progress, metric_given);
}

cv::Mat1f PanoramaDistances(const cv::Mat& rows, const cv::Mat& references, int strips,
                            PanoramaMatching mode, int threads, const PairProgress& progress,
                            std::optional<Metric> metric_given) {
  if (strips < 1)
    throw std::invalid_argument("PanoramaDistances: " + std::to_string(strips) +
                                " strips; expected >= 1");
  if (!references.empty() && (references.cols != rows.cols || references.type() != rows.type()))
    throw std::invalid_argument("PanoramaDistances: references of another width or type");
  if (rows.cols % strips != 0)
    throw std::invalid_argument("PanoramaDistances: row width " + std::to_string(rows.cols) +
                                " is not a multiple of " + std::to_string(strips) + " strips");
  const Metric metric = metric_given.value_or(MetricOfType(rows.type()));
  const bool squared = metric == Metric::kL2;  // Euclidean strips add up as squares
  auto distances = [&](const cv::Mat& a, const cv::Mat& b, const PairProgress& p) {
    return Distances(a, b, metric, threads, p);
  };
  if (mode == PanoramaMatching::kAligned || strips == 1)
    return distances(rows, references, progress);

  const cv::Mat& refs = references.empty() ? rows : references;
  const int n = rows.rows, m = refs.rows;
  const int w = rows.cols / strips;
  std::vector<cv::Mat> strip(static_cast<size_t>(strips)), ref_strip(strip.size());
  for (int k = 0; k < strips; ++k) {
    strip[static_cast<size_t>(k)] = rows.colRange(k * w, (k + 1) * w).clone();
    ref_strip[static_cast<size_t>(k)] = references.empty()
                                            ? strip[static_cast<size_t>(k)]
                                            : refs.colRange(k * w, (k + 1) * w).clone();
  }

  // Progress over the strips^2 single-strip matrices.
  const std::int64_t cells = static_cast<std::int64_t>(n) * m;
  const std::int64_t total = cells * strips * strips;
  std::int64_t offset = 0;
  const PairProgress inner = [&](std::int64_t done, std::int64_t) {
    if (progress) progress(offset + done, total);
  };
  auto strip_pair = [&](int k, int l) {
    cv::Mat1f d =
        distances(strip[static_cast<size_t>(k)], ref_strip[static_cast<size_t>(l)], inner);
    offset += cells;
    return d;
  };

  cv::Mat1f out = LargeMatrix(n, m);
  if (mode == PanoramaMatching::kCrossCorrelation) {
    // Eq. 3 and 4: the smallest distance over every pair of strips (k, l).
    for (int k = 0; k < strips; ++k)
      for (int l = 0; l < strips; ++l) {
        const cv::Mat1f d = strip_pair(k, l);
        if (k == 0 && l == 0) {
          d.copyTo(out);
        } else {
          MinInto(out, d);
        }
      }
    return out;
  }

  // Circular: for each shift s, the aligned distance against the strips of j turned by s.
  cv::Mat1f sum = LargeMatrix(n, m);
  for (int s = 0; s < strips; ++s) {
    for (int k = 0; k < strips; ++k) {
      cv::Mat1f d = strip_pair(k, (k + s) % strips);
      if (squared) cv::multiply(d, d, d);  // L2: squared strip distances add up
      if (k == 0) {
        d.copyTo(sum);
      } else {
        sum += d;
      }
    }
    if (squared) cv::sqrt(sum, sum);
    if (s == 0) {
      sum.copyTo(out);
    } else {
      MinInto(out, sum);
    }
  }
  return out;
}

}  // namespace openable
