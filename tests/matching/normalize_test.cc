#include "matching/normalize.h"

#include <gtest/gtest.h>

namespace openable {
namespace {

TEST(NormalizeByMax, DividesByTheMaximum) {
  cv::Mat1f m = (cv::Mat1f(2, 3) << 0, 2, 4, 8, 6, 1);
  EXPECT_FLOAT_EQ(NormalizeByMax(m), 8.f);
  const float expected[] = {0, 0.25f, 0.5f, 1, 0.75f, 0.125f};
  for (int k = 0; k < 6; ++k) EXPECT_FLOAT_EQ(m(k / 3, k % 3), expected[k]);
}

TEST(NormalizeByMax, AllZeroStaysZeroAndBadValuesThrow) {
  cv::Mat1f z(3, 3, 0.f);
  EXPECT_EQ(NormalizeByMax(z), 0.f);
  EXPECT_EQ(cv::countNonZero(z), 0);
  cv::Mat1f neg = (cv::Mat1f(1, 2) << 1, -1);
  EXPECT_THROW(NormalizeByMax(neg), std::logic_error);
  cv::Mat1f nan = (cv::Mat1f(1, 2) << 1, std::numeric_limits<float>::quiet_NaN());
  EXPECT_THROW(NormalizeByMax(nan), std::logic_error);
}

TEST(ThresholdMatrix, Equation9) {
  const cv::Mat1f m = (cv::Mat1f(1, 5) << 0.f, 0.19f, 0.2f, 0.21f, 1.f);
  const cv::Mat1b t = ThresholdMatrix(m, 0.2f);
  const int expected[] = {0, 0, 1, 1, 1};  // 0 where M' < theta
  for (int k = 0; k < 5; ++k) EXPECT_EQ(t(0, k), expected[k]) << k;
}

}  // namespace
}  // namespace openable
