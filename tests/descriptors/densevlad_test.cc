// DenseVLAD against its definition computed here from OpenCV's SIFT and plain loops: RootSIFT
// (Arandjelovic and Zisserman, CVPR 2012) on the dense grid, VLAD with intra-normalisation
// (Jegou et al., CVPR 2010; Arandjelovic and Zisserman, CVPR 2013), and a vocabulary learnt
// the same way from the same frames.
#include "descriptors/densevlad.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "descriptors/frame_describer.h"
#include "descriptors/registry.h"
#include "tests/descriptors/descriptor_test_util.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing_util::TexturedPatch;

// Frame i of the bundled Nordland sample's summer traversal (its files in name order), grey.
cv::Mat SampleFrame(int i) {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(
             testing::SourceDir() + "/examples/data/nordland_sample/summer"))
      out.push_back(e.path().string());
    std::sort(out.begin(), out.end());
    return out;
  }();
  return cv::imread(names.at(static_cast<size_t>(i)), cv::IMREAD_GRAYSCALE);
}

std::vector<cv::Mat> SampleFrames(int first, int count) {
  std::vector<cv::Mat> frames;
  for (int i = first; i < first + count; ++i) {
    cv::Mat f = SampleFrame(i);
    if (!f.empty()) frames.push_back(f);
  }
  return frames;
}

TEST(DenseVlad, RootSiftIsTheSquareRootOfL1NormalisedSiftOnTheDenseGrid) {
  const cv::Mat patch = TexturedPatch(96, 11);
  const cv::Mat1f rows = DenseVladDescriptor::DenseRootSift(patch);
  // The grid at each scale, described by OpenCV's SIFT here, then RootSIFT by hand.
  cv::Mat1f expected;
  for (const double scale : DenseVladDescriptor::Scales()) {
    cv::Mat image = patch;
    if (scale != 1.0)
      cv::resize(patch, image,
                 cv::Size(static_cast<int>(std::lround(96 * scale)),
                          static_cast<int>(std::lround(96 * scale))),
                 0, 0, cv::INTER_AREA);
    std::vector<cv::KeyPoint> points;
    for (int y = 2; y < image.rows; y += 4)
      for (int x = 2; x < image.cols; x += 4) points.emplace_back(x, y, 2.0f);
    cv::Mat sift;
    cv::SIFT::create()->compute(image, points, sift);
    for (int r = 0; r < sift.rows; ++r) {
      double l1 = 0;
      for (int c = 0; c < 128; ++c) l1 += sift.at<float>(r, c);
      cv::Mat1f row(1, 128);
      for (int c = 0; c < 128; ++c)
        row(0, c) = l1 > 0 ? static_cast<float>(std::sqrt(sift.at<float>(r, c) / l1)) : 0.0f;
      expected.push_back(row);
    }
  }
  ASSERT_EQ(rows.rows, expected.rows);
  ASSERT_EQ(rows.rows, 24 * 24 + 16 * 16 + 12 * 12);  // 96, 64 and 48 pixels at a step of 4
  EXPECT_LE(cv::norm(rows, expected, cv::NORM_INF), 1e-6);
  // Each row of a textured patch has unit L2 norm (the Hellinger kernel's property).
  for (int r = 0; r < rows.rows; ++r) {
    if (cv::countNonZero(rows.row(r)) > 0) {
      EXPECT_NEAR(cv::norm(rows.row(r)), 1.0, 1e-5);
    }
  }
}

TEST(DenseVlad, FramesWiderThanItsWidthAreShrunkKeepingTheirAspect) {
  const cv::Mat wide = TexturedPatch(640, 3)(cv::Rect(0, 0, 640, 200)).clone();
  // 320 x 100, 213 x 67, 160 x 50: 80 x 25 + 53 x 17 + 40 x 12 points (step 4, from 2).
  EXPECT_EQ(DenseVladDescriptor::DenseRootSift(wide).rows, 80 * 25 + 53 * 17 + 40 * 12);
}

TEST(DenseVlad, VladIsTheIntraNormalisedSumOfResidualsToTheNearestWord) {
  cv::RNG rng(7);
  cv::Mat1f local(50, 6), centres(4, 6);
  rng.fill(local, cv::RNG::UNIFORM, -1, 1);
  rng.fill(centres, cv::RNG::UNIFORM, -1, 1);
  const cv::Mat1f v = DenseVladDescriptor::Vlad(local, centres);
  // By hand: nearest word by the full L2 distance, residual sums, each word then the whole
  // normalised.
  std::vector<double> sums(24, 0.0);
  for (int i = 0; i < 50; ++i) {
    int best = 0;
    double best_d = 1e300;
    for (int k = 0; k < 4; ++k) {
      double d = 0;
      for (int e = 0; e < 6; ++e) d += std::pow(local(i, e) - centres(k, e), 2);
      if (d < best_d) best_d = d, best = k;
    }
    for (int e = 0; e < 6; ++e) sums[best * 6 + e] += local(i, e) - centres(best, e);
  }
  for (int k = 0; k < 4; ++k) {
    double n = 0;
    for (int e = 0; e < 6; ++e) n += sums[k * 6 + e] * sums[k * 6 + e];
    for (int e = 0; e < 6; ++e) sums[k * 6 + e] = n > 0 ? sums[k * 6 + e] / std::sqrt(n) : 0;
  }
  double total = 0;
  for (const double s : sums) total += s * s;
  ASSERT_EQ(v.cols, 24);
  for (int j = 0; j < 24; ++j) EXPECT_NEAR(v(0, j), sums[j] / std::sqrt(total), 1e-5) << j;
  // A word no descriptor chose stays zero; no descriptor at all gives the zero row.
  EXPECT_EQ(cv::countNonZero(DenseVladDescriptor::Vlad(cv::Mat1f(), centres)), 0);
}

TEST(DenseVlad, LearnsOneVocabularyFromTheSameFramesAndDescribesWithIt) {
  const std::vector<cv::Mat> frames = SampleFrames(0, 12);
  ASSERT_EQ(frames.size(), 12u);
  DescriptorOptions options;
  options.name = "DenseVLAD";
  const auto a = CreateDescriptor(options), b = CreateDescriptor(options);
  ASSERT_TRUE(a->Learns());
  EXPECT_EQ(a->Fingerprint(), "");
  cv::Mat1f row(1, a->Width());
  // Before learning: one line saying what to do.
  try {
    a->Describe(frames[0], row);
    FAIL() << "described without a vocabulary";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vocabulary learnt from a reference traversal"),
              std::string::npos);
  }
  a->Learn(frames);
  b->Learn(frames);
  const auto& va = static_cast<const DenseVladDescriptor&>(*a).Vocabulary();
  const auto& vb = static_cast<const DenseVladDescriptor&>(*b).Vocabulary();
  ASSERT_EQ(va.rows, DenseVladDescriptor::kCentres);
  EXPECT_EQ(cv::norm(va, vb, cv::NORM_INF), 0.0);
  EXPECT_FALSE(a->Fingerprint().empty());
  EXPECT_EQ(a->Fingerprint(), b->Fingerprint());
  // The row is the VLAD of the frame's dense RootSIFT over that vocabulary.
  a->Describe(frames[3], row);
  const cv::Mat1f expected =
      DenseVladDescriptor::Vlad(DenseVladDescriptor::DenseRootSift(frames[3]), va);
  EXPECT_LE(cv::norm(row, expected, cv::NORM_INF), 1e-6);
  EXPECT_NEAR(cv::norm(row), 1.0, 1e-5);
  // Other frames, another vocabulary.
  const auto c = CreateDescriptor(options);
  c->Learn(SampleFrames(100, 12));
  EXPECT_NE(c->Fingerprint(), a->Fingerprint());
}

TEST(DenseVlad, RefusesToLearnFromTooFewDescriptors) {
  DescriptorOptions options;
  options.name = "DenseVLAD";
  const auto d = CreateDescriptor(options);
  const std::vector<cv::Mat> tiny = {TexturedPatch(16, 1)};  // 16 + 9 + 4 descriptors
  try {
    d->Learn(tiny);
    FAIL() << "learnt 64 words from 29 descriptors";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected at least 256"), std::string::npos) << e.what();
  }
}

TEST(DenseVlad, AFrameOfTheSamePlaceIsNearerThanAnotherPlace) {
  // Frames 0 and 1 of the sample are one place a few metres apart; frame 150 another place.
  DescriptorOptions options;
  options.name = "DenseVLAD";
  const auto d = CreateDescriptor(options);
  d->Learn(SampleFrames(0, 40));
  cv::Mat1f r0(1, d->Width()), r1(1, d->Width()), r150(1, d->Width());
  d->Describe(SampleFrame(0), r0);
  d->Describe(SampleFrame(1), r1);
  d->Describe(SampleFrame(150), r150);
  EXPECT_LT(cv::norm(r0, r1), cv::norm(r0, r150));
}

TEST(DenseVlad, GridCellsAreAtLeastSixteenPixels) {
  DescriptorOptions options;
  options.name = "DenseVLAD";
  const auto d = CreateDescriptor(options);
  const FrameDescriber grid(*d, DescriptionType::kGrid, 2, 3);
  EXPECT_EQ(grid.MinimumFrame(), cv::Size(32, 48));
  EXPECT_EQ(grid.RowWidth(), 6 * d->Width());
}

}  // namespace
}  // namespace openable
