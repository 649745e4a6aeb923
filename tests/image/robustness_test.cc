// Side-window multilayer fusion and noise injection (OpenABLE/image/robustness.h).
#include "OpenABLE/image/robustness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/image/preprocess.h"
#include "config/config.h"
#include "tests/test_support.h"

namespace openable {
namespace {

// --- Side-window fusion against a brute force written from the paper's definition ----------

// Mean of rows [y0, y1] x columns [x0, x1], pixel by pixel, keeping only pixels inside.
double BruteMean(const std::vector<std::vector<double>>& im, int y0, int y1, int x0, int x1) {
  const int h = static_cast<int>(im.size()), w = static_cast<int>(im[0].size());
  double s = 0;
  int n = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (y >= 0 && y < h && x >= 0 && x < w) s += im[y][x], ++n;
  return s / n;
}

std::vector<std::vector<double>> BruteLayer(const std::vector<std::vector<double>>& im, int r) {
  const int h = static_cast<int>(im.size()), w = static_cast<int>(im[0].size());
  auto out = im;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // U, D, L, R, NW, NE, SW, SE: {top, bottom, left, right} offsets from the pixel.
      const int win[8][4] = {{-r, 0, -r, r}, {0, r, -r, r}, {-r, r, -r, 0}, {-r, r, 0, r},
                             {-r, 0, -r, 0}, {-r, 0, 0, r}, {0, r, -r, 0},  {0, r, 0, r}};
      double best = 1e300, value = 0;
      for (const auto& k : win) {
        const double q = BruteMean(im, y + k[0], y + k[1], x + k[2], x + k[3]);
        if (std::abs(q - im[y][x]) < best - 1e-9) best = std::abs(q - im[y][x]), value = q;
      }
      out[y][x] = value;
    }
  return out;
}

cv::Mat1b RandomImage(int rows, int cols, int seed) {
  cv::Mat1b im(rows, cols);
  cv::RNG rng(seed);
  rng.fill(im, cv::RNG::UNIFORM, 0, 256);
  return im;
}

TEST(SideWindow, OneLayerEqualsBruteForceForSeveralRadii) {
  const cv::Mat1b im = RandomImage(9, 11, 3);
  std::vector<std::vector<double>> b(9, std::vector<double>(11));
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 11; ++x) b[y][x] = im(y, x);
  cv::Mat1d d;
  im.convertTo(d, CV_64F);
  for (int r : {1, 2, 3, 6}) {  // 6: windows wider than half the image, clipped everywhere
    const cv::Mat1d got = SideWindowLayer(d, r);
    const auto want = BruteLayer(b, r);
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 11; ++x)
        ASSERT_NEAR(got(y, x), want[y][x], 1e-9) << r << " " << y << "," << x;
  }
}

// The interior of the image goes through a vectorised row loop: every output must be the very
// double of the clipped-box formula computed pixel by pixel (integral-image box sums, a
// division by the count, ties to the first window), on an image wide enough for full vectors,
// and within rounding of the brute-force means.
TEST(SideWindow, InteriorRowsAreTheSameDoublesAsThePixelByPixelFormula) {
  const int h = 37, w = 83;
  const cv::Mat1b im = RandomImage(h, w, 12);
  cv::Mat1d d;
  im.convertTo(d, CV_64F);
  std::vector<std::vector<double>> b(h, std::vector<double>(w));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) b[y][x] = im(y, x);
  for (int r : {1, 2, 3, 5}) {
    cv::Mat1d sum;
    cv::integral(d, sum, CV_64F);
    auto box = [&](int y0, int y1, int x0, int x1) {
      y0 = std::max(y0, 0), x0 = std::max(x0, 0);
      y1 = std::min(y1, h - 1), x1 = std::min(x1, w - 1);
      const double s = sum(y1 + 1, x1 + 1) - sum(y0, x1 + 1) - sum(y1 + 1, x0) + sum(y0, x0);
      return s / ((y1 - y0 + 1) * (x1 - x0 + 1));
    };
    const cv::Mat1d got = SideWindowLayer(d, r);
    const auto brute = BruteLayer(b, r);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double q[8] = {box(y - r, y, x - r, x + r), box(y, y + r, x - r, x + r),
                             box(y - r, y + r, x - r, x), box(y - r, y + r, x, x + r),
                             box(y - r, y, x - r, x),     box(y - r, y, x, x + r),
                             box(y, y + r, x - r, x),     box(y, y + r, x, x + r)};
        int k = 0;
        for (int n = 1; n < 8; ++n)
          if (std::abs(q[n] - d(y, x)) < std::abs(q[k] - d(y, x)) - 1e-9) k = n;
        ASSERT_EQ(got(y, x), q[k]) << "r " << r << " at " << y << "," << x;
        ASSERT_NEAR(got(y, x), brute[y][x], 1e-9) << "r " << r << " at " << y << "," << x;
      }
  }
}

TEST(SideWindow, StackedLayersEqualBruteForceAndRoundAtTheEnd) {
  const cv::Mat1b im = RandomImage(8, 13, 7);
  std::vector<std::vector<double>> b(8, std::vector<double>(13));
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 13; ++x) b[y][x] = im(y, x);
  const std::vector<int> radii = {1, 2, 3};
  for (int r : radii) b = BruteLayer(b, r);
  const cv::Mat out = SideWindowFusion(im, radii);
  ASSERT_EQ(out.type(), CV_8UC1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 13; ++x)
      EXPECT_EQ(out.at<uchar>(y, x), static_cast<int>(std::floor(b[y][x] + 0.5))) << y << "," << x;
  // The layers are not commutative in general: order matters (3,2,1 differs somewhere).
  EXPECT_GT(cv::norm(out, SideWindowFusion(im, {3, 2, 1}), cv::NORM_L1), 0);
}

TEST(SideWindow, CornerWindowsKeepTheCornersOfABlock) {
  // A 2x2 bright block (100) on black, radius 1, worked by hand: at each of its pixels only
  // the corner window lying over the block has mean 100 (the others mix in black).
  cv::Mat1b im(7, 7, uchar(0));
  im(2, 2) = im(2, 3) = im(3, 2) = im(3, 3) = 100;
  cv::Mat1d d;
  im.convertTo(d, CV_64F);
  const cv::Mat1d out = SideWindowLayer(d, 1);
  // (2, 2): the SE window {(2,2),(2,3),(3,2),(3,3)} has mean 100 = p: kept exactly.
  EXPECT_DOUBLE_EQ(out(2, 2), 100);  // SE
  EXPECT_DOUBLE_EQ(out(2, 3), 100);  // SW
  EXPECT_DOUBLE_EQ(out(3, 2), 100);  // NE
  EXPECT_DOUBLE_EQ(out(3, 3), 100);  // NW
  // (1, 2) (dark, above the block): U window (rows 0-1, cols 1-3) is all dark: 0.
  EXPECT_DOUBLE_EQ(out(1, 2), 0);
  // A box filter would have spread the block: (1, 2) gets 2/9 of 100 there.
  cv::Mat1d box;
  cv::blur(d, box, cv::Size(3, 3));
  EXPECT_NEAR(box(1, 2), 200.0 / 9, 1e-9);
}

TEST(SideWindow, StepEdgeStaysSharpWhereABoxFilterBlursIt) {
  cv::Mat1b im(20, 20, uchar(40));
  im.colRange(10, 20).setTo(200);
  const cv::Mat out = SideWindowFusion(im, {1, 2, 3});
  EXPECT_EQ(cv::norm(out, im, cv::NORM_INF), 0);  // every pixel unchanged: the edge is sharp
  cv::Mat blurred = im.clone();
  for (int r : {1, 2, 3}) cv::blur(blurred, blurred, cv::Size(2 * r + 1, 2 * r + 1));
  EXPECT_GT(std::abs(blurred.at<uchar>(10, 9) - 40), 30);  // the box filter blurs the edge
  EXPECT_GT(std::abs(blurred.at<uchar>(10, 10) - 200), 30);
}

TEST(SideWindow, NoisyStepEdgeIsSmoothedButKeepsItsContrast) {
  cv::Mat1b clean(30, 30, uchar(60));
  clean.colRange(15, 30).setTo(180);
  cv::Mat1s noise(30, 30);
  cv::RNG rng(11);
  rng.fill(noise, cv::RNG::NORMAL, 0, 12);
  cv::Mat1b noisy;
  cv::add(clean, noise, noisy, cv::noArray(), CV_8U);
  const cv::Mat out = SideWindowFusion(noisy, {1, 2, 3});
  // Less noise away from the edge, and the columns next to the edge stay on their side.
  EXPECT_LT(cv::norm(out, clean, cv::NORM_L2), 0.6 * cv::norm(noisy, clean, cv::NORM_L2));
  const double left = cv::mean(cv::Mat(out).col(14))[0], right = cv::mean(cv::Mat(out).col(15))[0];
  EXPECT_LT(left, 80);
  EXPECT_GT(right, 160);
}

TEST(SideWindow, ConstantImageIsUnchanged) {
  const cv::Mat1b im(17, 23, uchar(137));
  EXPECT_EQ(cv::norm(SideWindowFusion(im, {1, 4, 2}), im, cv::NORM_INF), 0);
}

TEST(SideWindow, TwoChannelImageFusesOnlyTheGrey) {
  const cv::Mat1b grey = RandomImage(10, 12, 1), disparity = RandomImage(10, 12, 2);
  cv::Mat both;
  cv::merge(std::vector<cv::Mat>{grey, disparity}, both);
  const cv::Mat out = SideWindowFusion(both, {2});
  cv::Mat c0, c1;
  cv::extractChannel(out, c0, 0);
  cv::extractChannel(out, c1, 1);
  EXPECT_EQ(cv::norm(c0, SideWindowFusion(grey, {2}), cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(c1, disparity, cv::NORM_INF), 0);
}

// --- Noise ------------------------------------------------------------------------------------

TEST(Noise, GaussianVarianceMatchesTheKey) {
  const cv::Mat frame(200, 300, CV_32FC1, cv::Scalar(0.5));
  NoiseOptions o;
  o.gaussian = 0.003;
  const cv::Mat noisy = AddNoise(frame, o, NoiseState(0, 0, 0));
  cv::Scalar mean, sd;
  cv::meanStdDev(noisy, mean, sd);
  // 60000 samples: the variance's relative standard error is sqrt(2 / 60000) = 0.6 %.
  EXPECT_NEAR(sd[0] * sd[0], 0.003, 0.003 * 0.03);
  EXPECT_NEAR(mean[0], 0.5, 0.002);
}

TEST(Noise, SaltAndPepperFractionMatchesTheKey) {
  const cv::Mat frame(200, 300, CV_32FC3, cv::Scalar(0.4, 0.5, 0.6));
  NoiseOptions o;
  o.salt_pepper = 0.1;
  const cv::Mat noisy = AddNoise(frame, o, NoiseState(3, 0, 5));
  int salt = 0, pepper = 0, other = 0;
  for (int y = 0; y < noisy.rows; ++y)
    for (int x = 0; x < noisy.cols; ++x) {
      const cv::Vec3f v = noisy.at<cv::Vec3f>(y, x);
      if (v == cv::Vec3f(1, 1, 1))
        ++salt;
      else if (v == cv::Vec3f(0, 0, 0))
        ++pepper;
      else if (v == cv::Vec3f(0.4f, 0.5f, 0.6f))
        continue;
      else
        ++other;
    }
  EXPECT_EQ(other, 0);
  // 60000 pixels, p = 0.1: sd of the fraction = 0.0012.
  EXPECT_NEAR((salt + pepper) / 60000.0, 0.1, 0.005);
  EXPECT_NEAR(salt / double(salt + pepper), 0.5, 0.03);
}

TEST(Noise, OverexposureMultipliesAndSaturates) {
  cv::Mat frame(1, 4, CV_32FC1);
  frame.at<float>(0, 0) = 0.1f, frame.at<float>(0, 1) = 0.3f, frame.at<float>(0, 2) = 0.6f,
                     frame.at<float>(0, 3) = 1.0f;
  NoiseOptions o;
  o.overexposure = 1.0;
  const cv::Mat out = AddNoise(frame, o, 1);
  EXPECT_FLOAT_EQ(out.at<float>(0, 0), 0.2f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 1), 0.6f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 2), 1.0f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 3), 1.0f);
}

TEST(Noise, SameSeedSameImageOtherFrameOrStreamOtherNoise) {
  const cv::Mat frame(40, 50, CV_32FC1, cv::Scalar(0.5));
  NoiseOptions o;
  o.gaussian = 0.003;
  o.salt_pepper = 0.1;
  const cv::Mat a = AddNoise(frame, o, NoiseState(7, 0, 12));
  EXPECT_EQ(cv::norm(a, AddNoise(frame, o, NoiseState(7, 0, 12)), cv::NORM_INF), 0);
  EXPECT_GT(cv::norm(a, AddNoise(frame, o, NoiseState(7, 0, 13)), cv::NORM_L1), 10);
  EXPECT_GT(cv::norm(a, AddNoise(frame, o, NoiseState(7, 1, 12)), cv::NORM_L1), 10);
  EXPECT_GT(cv::norm(a, AddNoise(frame, o, NoiseState(8, 0, 12)), cv::NORM_L1), 10);
  EXPECT_NE(NoiseState(0, 0, 1), NoiseState(0, 1, 0));
}

TEST(Noise, StereoFrameKeepsItsDisparity) {
  cv::Mat frame(20, 20, CV_32FC2, cv::Scalar(0.5, 0.25));
  NoiseOptions o;
  o.gaussian = 0.01;
  o.salt_pepper = 0.2;
  const cv::Mat out = AddNoise(frame, o, 4);
  cv::Mat c0, c1;
  cv::extractChannel(out, c0, 0);
  cv::extractChannel(out, c1, 1);
  EXPECT_GT(cv::norm(c0 - 0.5, cv::NORM_L1), 1);
  EXPECT_EQ(cv::norm(c1 - 0.25, cv::NORM_INF), 0);
}

// A descriptor that copies its 16x16 patch: rows then show the image that was described.
class RawDescriptor : public Descriptor {
 public:
  RawDescriptor() : Descriptor(Options16()) {}
  std::string Name() const override { return "RAW"; }
  int Width() const override { return 256; }
  DescriptorKind Kind() const override { return DescriptorKind::kFloat; }

 private:
  static DescriptorOptions Options16() {
    DescriptorOptions o;
    o.patch_size = 16;
    return o;
  }
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override {
    patch.reshape(1, 1).convertTo(row, CV_32F);
  }
};

class Frames : public FrameSource {
 public:
  explicit Frames(int n) : n_(n) {}
  int Size() const override { return n_; }
  std::string FrameName(int i) const override { return "f" + std::to_string(i); }
  cv::Mat Read(int) const override { return cv::Mat(16, 16, CV_32FC1, cv::Scalar(0.5)); }
  bool ParallelReads() const override { return true; }

 private:
  int n_;
};

TEST(Noise, DescribeSequenceIsIndependentOfThreadsAndDiffersByFrame) {
  RawDescriptor raw;
  const FrameDescriber d(raw, DescriptionType::kGlobal);
  const Frames src(24);
  DescribeOptions opt;
  opt.preprocess.noise.gaussian = 0.003;
  opt.preprocess.noise.salt_pepper = 0.1;
  opt.preprocess.noise.seed = 5;
  opt.preprocess.side_window = true;
  opt.preprocess.side_window_radii = "1,2";
  opt.threads = 1;
  const cv::Mat one = DescribeSequence(src, d, opt).rows;
  opt.threads = 4;
  const cv::Mat four = DescribeSequence(src, d, opt).rows;
  EXPECT_EQ(cv::norm(one, four, cv::NORM_INF), 0);
  // Frame i equals AddNoise with its own state, then grey, then fusion.
  for (int i : {0, 17}) {
    const cv::Mat grey = ToGray8(AddNoise(src.Read(i), opt.preprocess.noise, NoiseState(5, 0, i)));
    const cv::Mat fused = SideWindowFusion(grey, {1, 2});
    cv::Mat expect;
    fused.reshape(1, 1).convertTo(expect, CV_32F);
    EXPECT_EQ(cv::norm(one.row(i), expect, cv::NORM_INF), 0) << i;
  }
  EXPECT_GT(cv::norm(one.row(0), one.row(1), cv::NORM_L1), 100);  // frames get other noise
  opt.noise_stream = 1;  // the second traversal: other noise for the same index
  EXPECT_GT(cv::norm(DescribeSequence(src, d, opt).rows.row(0), one.row(0), cv::NORM_L1), 100);
  // Without noise or fusion, every row is the clean grey 128.
  DescribeOptions clean;
  EXPECT_EQ(cv::norm(DescribeSequence(src, d, clean).rows - 128, cv::NORM_INF), 0);
}

// --- Keys ---------------------------------------------------------------------------------------

TEST(RobustnessKeys, RadiiParseAndErrorsAreOneLineNamingTheKey) {
  EXPECT_EQ(ParseSideWindowRadii("1,2,3"), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(ParseSideWindowRadii(" 4 , 1 "), (std::vector<int>{4, 1}));
  EXPECT_EQ(ParseSideWindowRadii("2"), (std::vector<int>{2}));
  for (const char* bad : {"", "1,,2", "1,2,", "0", "51", "a", "1.5", "-1", "1;2",
                          "1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1"})
    testing::ExpectInputError([&] { ParseSideWindowRadii(bad); },
                              {"Side_window_radii", "expected radii in [1, 50]"});
  Config c;
  c.input.images_path = "x";
  c.preprocess.side_window = true;
  c.preprocess.side_window_radii = "1,x";
  testing::ExpectInputError([&] { CheckConfig(c); }, {"Side_window_radii", "\"x\""});
  c.preprocess.side_window = false;
  CheckConfig(c);  // not used when off
}

TEST(RobustnessKeys, NoiseKeysAreBoundedWithOneLineErrors) {
  Config c;
  testing::ExpectInputError([&] { ApplyOverride(c, "Noise_gaussian=-0.1"); },
                            {"Noise_gaussian", "number in [0, 1]"});
  testing::ExpectInputError([&] { ApplyOverride(c, "Noise_salt_pepper=1.5"); },
                            {"Noise_salt_pepper", "number in [0, 1]"});
  testing::ExpectInputError([&] { ApplyOverride(c, "Noise_overexposure=-1"); },
                            {"Noise_overexposure", "number >= 0"});
  testing::ExpectInputError([&] { ApplyOverride(c, "Noise_seed=1.5"); }, {"Noise_seed"});
  testing::ExpectInputError([&] { ApplyOverride(c, "Side_window=2"); }, {"Side_window"});
  ApplyOverride(c, "Noise_gaussian=0.003");
  ApplyOverride(c, "Side_window_radii=\"2,2\"");
  EXPECT_DOUBLE_EQ(c.preprocess.noise.gaussian, 0.003);
  EXPECT_EQ(c.preprocess.side_window_radii, "2,2");
}

}  // namespace
}  // namespace openable
