// SAD (descriptors/sad.h): the thumbnail, the patch normalisation and the bytes, against a
// direct computation written out here; the settings and their errors.
#include "descriptors/sad.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/base/error.h"
#include "descriptors/registry.h"
#include "tests/descriptors/descriptor_test_util.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing_util::Describe;

// A patch whose area resize to S x S/2 is exact: pairs of identical rows, so each thumbnail
// pixel is one of them, with no rounding.
cv::Mat PairedRows(int size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat p(size, size, CV_8U);
  for (int y = 0; y < size; y += 2)
    for (int x = 0; x < size; ++x)
      p.at<std::uint8_t>(y, x) = p.at<std::uint8_t>(y + 1, x) =
          static_cast<std::uint8_t>(rng.uniform(0, 256));
  return p;
}

// The expected row, written from the definition: thumbnail pixel (x, y) = patch (x, 2y); each
// square of side `sq` (smaller at the right and bottom edges) normalised by its own mean and
// population standard deviation; byte = clamp(round(128 + 32 z)).
std::vector<int> Expected(const cv::Mat& patch, int sq) {
  const int w = patch.cols, h = patch.rows / 2;
  std::vector<int> row(w * h);
  for (int y0 = 0; y0 < h; y0 += sq)
    for (int x0 = 0; x0 < w; x0 += sq) {
      const int y1 = y0 + sq < h ? y0 + sq : h, x1 = x0 + sq < w ? x0 + sq : w;
      double sum = 0, n = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) sum += patch.at<std::uint8_t>(2 * y, x), n += 1;
      const double mean = sum / n;
      double var = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const double d = patch.at<std::uint8_t>(2 * y, x) - mean;
          var += d * d;
        }
      const double sd = std::sqrt(var / n);
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
          const double z = sd > 0 ? (patch.at<std::uint8_t>(2 * y, x) - mean) / sd : 0.0;
          long b = std::lround(128 + 32 * z);
          row[y * w + x] = static_cast<int>(b < 0 ? 0 : b > 255 ? 255 : b);
        }
    }
  return row;
}

void ExpectRow(const cv::Mat& row, const std::vector<int>& expected) {
  ASSERT_EQ(row.cols, static_cast<int>(expected.size()));
  int off = 0;
  for (int i = 0; i < row.cols; ++i) off += row.at<std::uint8_t>(0, i) != expected[i];
  EXPECT_EQ(off, 0) << "bytes that differ from the direct computation";
}

TEST(Sad, RowIsThePatchNormalisedThumbnail) {
  DescriptorOptions o;
  const SadDescriptor sad(o);
  EXPECT_EQ(sad.ThumbnailSize(), cv::Size(64, 32));
  EXPECT_EQ(sad.Width(), 2048);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const cv::Mat patch = PairedRows(64, seed);
    ExpectRow(Describe(sad, patch), Expected(patch, 8));
  }
}

TEST(Sad, SquaresThatDoNotDivideTheSidesAreCutAtTheEdges) {
  DescriptorOptions o;
  o.patch_size = 40;  // thumbnail 40 x 20
  o.sad_patch = 6;    // squares 6 x 6, then 4 wide at the right and 2 high at the bottom
  const SadDescriptor sad(o);
  const cv::Mat patch = PairedRows(40, 9);
  ExpectRow(Describe(sad, patch), Expected(patch, 6));
}

TEST(Sad, UniformSquaresBecomeZeroAndContrastIsNormalisedAway) {
  DescriptorOptions o;
  const SadDescriptor sad(o);
  const cv::Mat flat(64, 64, CV_8U, cv::Scalar(77));
  const cv::Mat row = Describe(sad, flat);
  EXPECT_EQ(cv::countNonZero(row != 128), 0);
  // A patch and the same patch with half the contrast and another brightness: each square's
  // z values are the same, up to the rounding of the pixels.
  const cv::Mat patch = PairedRows(64, 4);
  cv::Mat dim;
  patch.convertTo(dim, CV_8U, 0.5, 40);
  const cv::Mat a = Describe(sad, patch), b = Describe(sad, dim);
  double worst = 0;
  for (int i = 0; i < a.cols; ++i)
    worst = std::max(worst, std::abs(double(a.at<std::uint8_t>(0, i)) - b.at<std::uint8_t>(0, i)));
  EXPECT_LE(worst, 3.0);  // half a grey level of rounding is at most ~2 bytes at sigma ~ 37
}

TEST(Sad, TwoValuedSquareGivesPlusAndMinusOneDeviation) {
  // Hand computation: a square of half 0 and half 200 has mean 100 and deviation 100, so every
  // pixel is z = +-1: bytes 96 and 160.
  DescriptorOptions o;
  o.patch_size = 16;  // thumbnail 16 x 8: two 8 x 8 squares
  const SadDescriptor sad(o);
  cv::Mat patch(16, 16, CV_8U, cv::Scalar(0));
  patch(cv::Rect(0, 0, 16, 8)).setTo(200);  // thumbnail rows 0-3 are 200, rows 4-7 are 0
  const cv::Mat row = Describe(sad, patch);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      EXPECT_EQ(row.at<std::uint8_t>(0, y * 16 + x), y < 4 ? 160 : 96) << x << "," << y;
}

TEST(Sad, SettingsOutOfRangeNameTheKey) {
  DescriptorOptions o;
  o.sad_patch = 1;
  testing::ExpectInputError([&] { SadDescriptor d(o); }, {"Sad_patch: 1", "[2, 64]"});
  o.sad_patch = 20;
  o.patch_size = 32;  // thumbnail 32 x 16
  testing::ExpectInputError([&] { SadDescriptor d(o); }, {"Sad_patch: 20", "at most 16"});
  o.sad_patch = 16;
  EXPECT_NO_THROW(SadDescriptor d(o));
}

TEST(Sad, IsRegisteredWithBytesAndTheL1Distance) {
  const auto d = CreateDescriptor("sad", DescriptorOptions());
  EXPECT_EQ(d->Name(), "SAD");
  EXPECT_EQ(d->Kind(), DescriptorKind::kBytes);
  EXPECT_EQ(d->Distance(), DistanceKind::kL1);
  EXPECT_EQ(RowType(*d), CV_8U);
}

}  // namespace
}  // namespace openable
