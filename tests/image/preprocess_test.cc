// Illumination invariance (Eq. 6, 7 of the OpenABLE paper).
#include "OpenABLE/image/preprocess.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/frame_source.h"
#include "tests/test_support.h"

namespace openable {
namespace {

// Eq. 7 with the numbers the paper gives for KITTI's PointGrey Flea2: alpha = 0.47.
TEST(Alpha, FromPeakResponsesOfTheKittiCamera) {
  const double a = AlphaFromPeakResponses(610, 535, 470);
  // (470/535 - 470/610) / (1 - 470/610), worked by hand: 0.1080129 / 0.2295082 = 0.4706275.
  EXPECT_NEAR(a, 0.4706275, 1e-6);
  EXPECT_NEAR(a, 0.47, 0.005);  // the paper's rounded figure
}

TEST(Alpha, RejectsResponsesOutOfOrder) {
  testing::ExpectInputError([] { AlphaFromPeakResponses(470, 535, 610); },
                            {"Lambda_red", "470", "expected 0 < blue < green < red"});
  testing::ExpectInputError([] { AlphaFromPeakResponses(610, 535, 0); }, {"Lambda_blue"});
}

// Every pixel against Eq. 6 computed here in double precision and mapped as the header says.
TEST(IlluminationInvariant, EqualsEquationSixPixelByPixel) {
  cv::Mat frame(7, 9, CV_32FC3);
  cv::RNG rng(5);
  rng.fill(frame, cv::RNG::UNIFORM, 0.0, 1.0);
  frame.at<cv::Vec3f>(0, 0) = cv::Vec3f(0, 0.5f, 0.25f);  // B = 0: floored at 1/510
  const double alpha = 0.47;
  const cv::Mat1b out = IlluminationInvariant(frame, alpha);
  ASSERT_EQ(out.size(), frame.size());
  for (int y = 0; y < frame.rows; ++y)
    for (int x = 0; x < frame.cols; ++x) {
      const cv::Vec3f p = frame.at<cv::Vec3f>(y, x);
      auto l = [](double v) { return std::log(std::max(v, 1.0 / 510.0)); };
      const double i = l(p[1]) - alpha * l(p[0]) - (1 - alpha) * l(p[2]);
      const double expected = std::min(255.0, std::max(0.0, 255.0 * (0.5 + i / 2)));
      EXPECT_NEAR(out(y, x), expected, 0.51) << y << "," << x;
    }
}

// The point of Eq. 6: a change of light intensity (all channels scaled by k) leaves I unchanged,
// since log(kG) - a log(kB) - (1 - a) log(kR) = I + log k (1 - a - (1 - a)) = I.
TEST(IlluminationInvariant, UnchangedWhenTheLightIsDimmed) {
  cv::Mat frame(16, 16, CV_32FC3);
  cv::RNG rng(11);
  rng.fill(frame, cv::RNG::UNIFORM, 0.2, 0.9);
  const cv::Mat1b bright = IlluminationInvariant(frame, 0.47);
  const cv::Mat1b dim = IlluminationInvariant(frame * 0.3, 0.47);
  EXPECT_LE(cv::norm(bright, dim, cv::NORM_INF), 1.0);
  // whereas the grey image changes a lot
  cv::Mat grey_bright, grey_dim;
  cv::Mat(ToGray8(frame)).convertTo(grey_bright, CV_32F);
  cv::Mat(ToGray8(frame * 0.3)).convertTo(grey_dim, CV_32F);
  EXPECT_GT(cv::norm(grey_bright, grey_dim, cv::NORM_INF), 50.0);
}

TEST(IlluminationInvariant, RejectsGreyFrames) {
  testing::ExpectInputError(
      [] { IlluminationInvariant(cv::Mat(4, 4, CV_32FC1, cv::Scalar(0.5)), 0.47); },
      {"1 channel", "colour"});
  testing::ExpectInputError(
      [] { IlluminationInvariant(cv::Mat(4, 4, CV_32FC3, cv::Scalar(0.3, 0.3, 0.3)), 0.47); },
      {"grey", "R = G = B"});
}

// A real colour frame (Gardens Point) dimmed to 40 %: the invariant image barely moves.
TEST(IlluminationInvariant, RealFrameDimmed) {
  const std::string path = testing::DatasetsDir() + "/gardens_point/day_left/Image000.jpg";
  OPENABLE_REQUIRE_PATH(path);
  const cv::Mat frame = ReadImageFile(path);
  ASSERT_EQ(frame.channels(), 3);
  const cv::Mat1b a = IlluminationInvariant(frame, 0.47);
  const cv::Mat1b b = IlluminationInvariant(frame * 0.4, 0.47);
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  // Pixels near black are floored (1/510) and do move; the rest moves by at most rounding.
  EXPECT_GT(cv::countNonZero(diff <= 1), 0.9 * diff.total());
}

}  // namespace
}  // namespace openable
