#include "descriptors/ldb.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

constexpr int kLevels[] = {2, 3, 4, 5};
constexpr int kCellCount = 4 + 9 + 16 + 25;
constexpr int kFeaturesPerCell = 3;  // I_avg, G_x, G_y
constexpr std::size_t kFeatureCount = std::size_t{kFeaturesPerCell} * kCellCount;

}  // namespace

std::vector<int> LdbSelectedTests(int bits, LdbSelection selection) {
  if (bits < 1 || bits > kLdbTotalTests) {
    throw std::logic_error("LdbSelectedTests: bits " + std::to_string(bits) + " outside [1, " +
                           std::to_string(kLdbTotalTests) + "]");
  }
  std::vector<int> order(kLdbTotalTests);
  std::iota(order.begin(), order.end(), 0);
  if (selection == LdbSelection::kRandom && bits < kLdbTotalTests) {
    // Fisher-Yates on raw mt19937 outputs (std::shuffle and uniform_int_distribution are
    // implementation-defined). The modulo bias is below 1386 / 2^32 and is part of the spec.
    std::mt19937 generator(kLdbSelectionSeed);
    for (int i = kLdbTotalTests - 1; i > 0; --i) {
      const auto out = static_cast<std::uint32_t>(generator());
      const int j = static_cast<int>(out % static_cast<std::uint32_t>(i + 1));
      std::swap(order[i], order[j]);
    }
  }
  order.resize(bits);
  return order;
}

LdbDescriptor::LdbDescriptor(const DescriptorOptions& options, LdbSelection selection)
    : Descriptor(options), bits_(options.ldb_bits), selection_(selection) {
  const long long s = PatchSize();
  cells_.reserve(kCellCount);
  for (const int n : kLevels) {
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        Cell cell{};
        cell.y0 = static_cast<int>(r * s / n);
        cell.y1 = static_cast<int>((r + 1) * s / n);
        cell.x0 = static_cast<int>(c * s / n);
        cell.x1 = static_cast<int>((c + 1) * s / n);
        cell.xm = (cell.x0 + cell.x1) / 2;
        cell.ym = (cell.y0 + cell.y1) / 2;
        cells_.push_back(cell);
      }
    }
  }

  // Canonical test order: level, then pair (i, j) with i < j, then feature.
  std::vector<Test> canonical;
  canonical.reserve(kLdbTotalTests);
  int base = 0;  // index of the level's first cell in cells_
  for (const int n : kLevels) {
    const int count = n * n;
    for (int i = 0; i < count; ++i) {
      for (int j = i + 1; j < count; ++j) {
        for (int k = 0; k < kFeaturesPerCell; ++k) {
          canonical.push_back({static_cast<std::uint16_t>(kFeaturesPerCell * (base + i) + k),
                               static_cast<std::uint16_t>(kFeaturesPerCell * (base + j) + k)});
        }
      }
    }
    base += count;
  }
  if (static_cast<int>(canonical.size()) != kLdbTotalTests ||
      static_cast<int>(cells_.size()) != kCellCount) {
    throw std::logic_error("LdbDescriptor: test table has the wrong size");
  }

  selected_ = LdbSelectedTests(bits_, selection_);
  tests_.reserve(selected_.size());
  for (const int t : selected_) {
    tests_.push_back(canonical[t]);
  }
}

void LdbDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  // Sums of up to 255 * S^2 are exact in double for any practical S.
  cv::Mat integral;
  cv::integral(patch, integral, CV_64F);
  const auto box = [&integral](int y0, int y1, int x0, int x1) {
    const double* top = integral.ptr<double>(y0);
    const double* bottom = integral.ptr<double>(y1);
    return bottom[x1] - bottom[x0] - top[x1] + top[x0];
  };
  const auto mean = [&box](int y0, int y1, int x0, int x1) {
    return box(y0, y1, x0, x1) / (static_cast<double>(y1 - y0) * (x1 - x0));
  };

  std::array<double, kFeatureCount> features;
  for (std::size_t i = 0; i < cells_.size(); ++i) {
    const Cell& c = cells_[i];
    features[kFeaturesPerCell * i + 0] = mean(c.y0, c.y1, c.x0, c.x1);
    features[kFeaturesPerCell * i + 1] =
        mean(c.y0, c.y1, c.xm, c.x1) - mean(c.y0, c.y1, c.x0, c.xm);
    features[kFeaturesPerCell * i + 2] =
        mean(c.ym, c.y1, c.x0, c.x1) - mean(c.y0, c.ym, c.x0, c.x1);
  }

  auto* out = row.ptr<std::uint8_t>(0);
  std::fill(out, out + Width(), std::uint8_t{0});
  for (std::size_t k = 0; k < tests_.size(); ++k) {
    if (features[tests_[k].a] < features[tests_[k].b]) {
      out[k >> 3] = static_cast<std::uint8_t>(out[k >> 3] | (1u << (k & 7u)));
    }
  }
}

}  // namespace openable
