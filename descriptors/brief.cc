#include "descriptors/brief.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

// Two standard normal deviates from two raw 32-bit outputs (Box-Muller, in double).
void NormalPair(std::mt19937& generator, double* z0, double* z1) {
  constexpr double kTwoTo32 = 4294967296.0;
  constexpr double kTwoPi = 6.283185307179586476925286766559;
  const double a = static_cast<double>(static_cast<std::uint32_t>(generator()));
  const double b = static_cast<double>(static_cast<std::uint32_t>(generator()));
  const double u1 = (a + 0.5) / kTwoTo32;
  const double u2 = (b + 0.5) / kTwoTo32;
  const double r = std::sqrt(-2.0 * std::log(u1));
  *z0 = r * std::cos(kTwoPi * u2);
  *z1 = r * std::sin(kTwoPi * u2);
}

int ToPixel(double z, int s) {
  const double v = std::floor(s / 2.0 + z * s / 5.0);
  return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(s - 1)));
}

}  // namespace

const std::array<BriefUnitTest, kBriefTests>& BriefUnitPattern() {
  static const std::array<BriefUnitTest, kBriefTests> pattern = [] {
    std::array<BriefUnitTest, kBriefTests> p{};
    std::mt19937 generator(kBriefPatternSeed);
    for (BriefUnitTest& t : p) {
      NormalPair(generator, &t.x_col, &t.x_row);
      NormalPair(generator, &t.y_col, &t.y_row);
    }
    return p;
  }();
  return pattern;
}

BriefDescriptor::BriefDescriptor(const DescriptorOptions& options) : Descriptor(options) {
  half_ = std::max(1, static_cast<int>(std::lround(4.0 * PatchSize() / 48.0)));
  tests_.reserve(kBriefTests);
  for (const BriefUnitTest& t : BriefUnitPattern()) {
    tests_.push_back({ToPixel(t.x_col, PatchSize()), ToPixel(t.x_row, PatchSize()),
                      ToPixel(t.y_col, PatchSize()), ToPixel(t.y_row, PatchSize())});
  }
}

void BriefDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  // Sums up to 255 * S^2 fit in 32 bits for any S below 2900.
  cv::Mat integral;
  cv::integral(patch, integral, CV_32S);
  const int s = PatchSize();
  const int h = half_;
  // Sum and pixel count of the box around (col, row) clipped to the patch.
  const auto box = [&](int col, int r, std::int64_t* count) {
    const int x0 = std::max(0, col - h), x1 = std::min(s, col + h + 1);
    const int y0 = std::max(0, r - h), y1 = std::min(s, r + h + 1);
    const int* top = integral.ptr<int>(y0);
    const int* bottom = integral.ptr<int>(y1);
    *count = static_cast<std::int64_t>(x1 - x0) * (y1 - y0);
    return static_cast<std::int64_t>(bottom[x1]) - bottom[x0] - top[x1] + top[x0];
  };

  auto* out = row.ptr<std::uint8_t>(0);
  std::fill(out, out + Width(), std::uint8_t{0});
  for (std::size_t k = 0; k < tests_.size(); ++k) {
    const BriefPixelTest& t = tests_[k];
    std::int64_t nx = 0, ny = 0;
    const std::int64_t sx = box(t.x_col, t.x_row, &nx);
    const std::int64_t sy = box(t.y_col, t.y_row, &ny);
    if (sx * ny < sy * nx) {  // mean at x < mean at y
      out[k >> 3] = static_cast<std::uint8_t>(out[k >> 3] | (1u << (k & 7u)));
    }
  }
}

}  // namespace openable
