#include "descriptors/opencv_descriptors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "tests/descriptors/descriptor_test_util.h"

namespace openable {
namespace {

using namespace testing_util;  // NOLINT: the descriptor test helpers are this file's vocabulary

double L2(const cv::Mat& a, const cv::Mat& b) {
  double sum = 0.0;
  for (int i = 0; i < a.cols; ++i) {
    const double diff = static_cast<double>(a.at<float>(0, i)) - b.at<float>(0, i);
    sum += diff * diff;
  }
  return std::sqrt(sum);
}

double Norm(const cv::Mat& a) { return L2(a, cv::Mat::zeros(a.size(), a.type())); }

// The descriptor distance between two rows, normalised to [0, 1]-ish: bits differing over all
// bits, or L2 difference over the first row's norm.
double RelativeChange(const Descriptor& d, const cv::Mat& a, const cv::Mat& b) {
  if (d.Kind() == DescriptorKind::kBinary) return Hamming(a, b) / (8.0 * a.cols);
  return L2(a, b) / Norm(a);
}

std::vector<std::unique_ptr<Descriptor>> AllThree(int patch_size) {
  std::vector<std::unique_ptr<Descriptor>> out;
  out.push_back(std::make_unique<OrbDescriptor>(Options(patch_size)));
  out.push_back(std::make_unique<BriskDescriptor>(Options(patch_size)));
  out.push_back(std::make_unique<SiftDescriptor>(Options(patch_size)));
  return out;
}

TEST(OpenCvDescriptors, OrbKeepsTheKeypointAtEveryPatchSize) {
  // The original OpenABLE forced 128 pixels for ORB; every size from 16 up must work.
  for (int size = 16; size <= 140; ++size) {
    const OrbDescriptor orb(Options(size));
    cv::Mat row;
    ASSERT_NO_THROW(row = Describe(orb, TexturedPatch(size, size))) << "patch size " << size;
    EXPECT_GT(cv::countNonZero(row), 0) << "patch size " << size;
  }
}

TEST(OpenCvDescriptors, BriskAndSiftKeepTheKeypointAtAssortedPatchSizes) {
  for (const int size : {16, 17, 18, 19, 20, 23, 31, 32, 33, 63, 64, 65, 100, 127, 128, 200}) {
    const BriskDescriptor brisk(Options(size));
    const SiftDescriptor sift(Options(size));
    const cv::Mat patch = TexturedPatch(size, 7u * static_cast<unsigned>(size));
    cv::Mat row;
    ASSERT_NO_THROW(row = Describe(brisk, patch)) << "BRISK, patch size " << size;
    EXPECT_GT(cv::countNonZero(row), 0) << "BRISK, patch size " << size;
    ASSERT_NO_THROW(row = Describe(sift, patch)) << "SIFT, patch size " << size;
    EXPECT_GT(cv::countNonZero(row), 0) << "SIFT, patch size " << size;
  }
}

TEST(OpenCvDescriptors, BriskScaleIsTheDiscreteScaleNearestThePatch) {
  // OpenCV's BRISK scales are f = 30^(i/64); size 7.2 f; outer ring radius 0.85 * 10.8 f.
  // For S = 64: S / 2 / 9.18 = 3.486, log_30(3.486) * 64 = 23.50 -> i = 23 (worked out by hand).
  EXPECT_NEAR(BriskDescriptor(Options(64)).KeypointSize(), 7.2 * std::pow(30.0, 23.0 / 64.0), 1e-4);
  EXPECT_NEAR(BriskDescriptor(Options(16)).KeypointSize(), 7.2, 1e-5);  // smallest scale
  for (const int size : {19, 24, 40, 64, 100, 128, 300}) {
    const double radius = 0.85 * 10.8 * BriskDescriptor(Options(size)).KeypointSize() / 7.2;
    const double half_step = std::pow(30.0, 0.5 / 64.0);
    EXPECT_LE(radius, 0.5 * size * half_step * 1.0001) << size;
    EXPECT_GE(radius, 0.5 * size / half_step / 1.0001) << size;
  }
}

TEST(OpenCvDescriptors, BriskDoesNotNormaliseOrientation) {
  // OpenCV's own BRISK steers its pattern to the estimated orientation, which makes a patch and
  // its 90-degree rotation nearly identical; with angle 0 kept they differ like unrelated
  // patches (about half the 512 bits).
  const BriskDescriptor brisk(Options(64));
  for (int seed = 0; seed < 3; ++seed) {
    const cv::Mat patch = TexturedPatch(64, 40 + seed);
    cv::Mat rotated;
    cv::rotate(patch, rotated, cv::ROTATE_90_CLOCKWISE);
    EXPECT_GT(Hamming(Describe(brisk, patch), Describe(brisk, rotated)), 128) << seed;
  }
}

// An 8 x 8 block of the patch, inverted.
cv::Mat InvertBlock(const cv::Mat& patch, int y, int x) {
  cv::Mat out = patch.clone();
  cv::Mat block = out(cv::Rect(x, y, 8, 8));
  cv::bitwise_not(block, block);
  return out;
}

TEST(OpenCvDescriptors, DescriptorsReadTheWholePatch) {
  // A change at the middle of each side of the patch (on the inscribed circle) changes every
  // descriptor; for SIFT, whose grid is square, so does a change in each corner.
  const int s = 64;
  const cv::Mat patch = TexturedPatch(s, 55);
  for (const auto& d : AllThree(s)) {
    const cv::Mat original = Describe(*d, patch);
    const std::vector<cv::Point> sides = {{28, 0}, {28, 56}, {0, 28}, {56, 28}};
    for (const cv::Point& p : sides) {
      EXPECT_GT(RelativeChange(*d, original, Describe(*d, InvertBlock(patch, p.y, p.x))), 0.0)
          << d->Name() << ": block at x " << p.x << ", y " << p.y;
    }
  }
  const SiftDescriptor sift(Options(s));
  const cv::Mat original = Describe(sift, patch);
  for (const cv::Point& p : std::vector<cv::Point>{{0, 0}, {56, 0}, {0, 56}, {56, 56}}) {
    EXPECT_GT(L2(original, Describe(sift, InvertBlock(patch, p.y, p.x))), 0.0)
        << "SIFT: corner block at x " << p.x << ", y " << p.y;
  }
}

// The patch at the centre of a larger image of unrelated texture.
cv::Mat Embed(const cv::Mat& patch, std::uint64_t seed) {
  const int s = patch.rows;
  cv::Mat big = TexturedPatch(3 * s, seed);
  patch.copyTo(big(cv::Rect(s, s, s, s)));
  return big;
}

TEST(OpenCvDescriptors, DescriptorsReadLittleBeyondThePatch) {
  // Describing the patch on its own (reflected border) and inside unrelated surroundings, at the
  // documented centre and scale with OpenCV directly, gives nearly the same descriptor: the
  // window is the patch, not much more. A much larger window would read mostly surroundings.
  const int s = 64;
  const float centre = s + 0.5f * (s - 1);
  const BriskDescriptor brisk(Options(s));
  // BRISK's standard pattern (OpenCV's default), with no long pairs.
  const std::vector<float> radii = {0.0f, static_cast<float>(0.85 * 2.9),
                                    static_cast<float>(0.85 * 4.9), static_cast<float>(0.85 * 7.4),
                                    static_cast<float>(0.85 * 10.8)};
  const std::vector<int> points = {1, 10, 14, 15, 20};
  struct Case {
    std::unique_ptr<Descriptor> ours;
    cv::Ptr<cv::Feature2D> opencv;
    float size;
    double limit;
  };
  std::vector<Case> cases;
  cases.push_back({std::make_unique<OrbDescriptor>(Options(s)),
                   cv::ORB::create(500, 1.2f, 1, s, 0, 2, cv::ORB::HARRIS_SCORE, s),
                   static_cast<float>(s), 0.10});
  cases.push_back({std::make_unique<BriskDescriptor>(Options(s)),
                   cv::BRISK::create(30, 0, radii, points, 5.85f, 1000.0f), brisk.KeypointSize(),
                   0.15});
  // SIFT's trilinear interpolation reaches half a cell beyond its grid: measured 0.32 at the
  // documented size S / 6, 0.49 at S / 4, 0.50 at S / 3, 0.01 at S / 8.
  cases.push_back(
      {std::make_unique<SiftDescriptor>(Options(s)), cv::SIFT::create(), s / 6.0f, 0.40});
  for (Case& c : cases) {
    double total = 0.0;
    constexpr int kTrials = 4;
    for (int t = 0; t < kTrials; ++t) {
      const cv::Mat patch = TexturedPatch(s, 60 + t);
      std::vector<cv::KeyPoint> keypoints = {cv::KeyPoint(centre, centre, c.size, 0.0f)};
      cv::Mat in_context;
      c.opencv->compute(Embed(patch, 70 + t), keypoints, in_context);
      ASSERT_EQ(in_context.rows, 1) << c.ours->Name();
      total += RelativeChange(*c.ours, Describe(*c.ours, patch), in_context);
    }
    const double mean = total / kTrials;
    std::printf("%s: mean relative change in context %.3f\n", c.ours->Name().c_str(), mean);
    EXPECT_LT(mean, c.limit) << c.ours->Name();
    EXPECT_GT(mean, 0.0) << c.ours->Name() << " should read a little of the border";
  }
}

}  // namespace
}  // namespace openable
