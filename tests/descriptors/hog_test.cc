#include "descriptors/hog.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "OpenABLE/base/error.h"
#include "tests/descriptors/descriptor_test_util.h"

namespace openable {
namespace {

using testing_util::Describe;
using testing_util::Options;
using testing_util::TexturedPatch;

TEST(HogTest, WidthIsBlocksTimesThirtySix) {
  // ((S - 16) / 8 + 1)^2 blocks of 2 x 2 cells x 9 bins.
  EXPECT_EQ(HogDescriptor(Options(64)).Width(), 7 * 7 * 36);  // 1764
  EXPECT_EQ(HogDescriptor(Options(32)).Width(), 3 * 3 * 36);
  EXPECT_EQ(HogDescriptor(Options(16)).Width(), 36);
  EXPECT_EQ(HogDescriptor(Options(128)).Width(), 15 * 15 * 36);
}

TEST(HogTest, RejectsPatchSizesThatAreNotWholeCells) {
  for (const int size : {60, 17, 8, 0}) {
    try {
      HogDescriptor d(Options(size));
      ADD_FAILURE() << "no error for " << size;
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("Patch_size"), std::string::npos) << m;
      EXPECT_NE(m.find(std::to_string(size)), std::string::npos) << m;
    }
  }
}

TEST(HogTest, HorizontalEdgeFillsOnlyTheVerticalGradientBin) {
  // Top half 0, bottom half 200: every gradient points straight down (90 degrees), which with
  // 9 unsigned bins of 20 degrees centred at 10, 30, ..., 170 falls exactly on bin 4 (90 deg).
  cv::Mat patch(64, 64, CV_8UC1, cv::Scalar(0));
  patch.rowRange(32, 64).setTo(200);
  const HogDescriptor hog(Options(64));
  const cv::Mat row = Describe(hog, patch);
  double in_bin4 = 0.0;
  for (int i = 0; i < row.cols; ++i) {
    const float v = row.at<float>(0, i);
    if (i % 9 == 4) {
      in_bin4 += v;
    } else {
      EXPECT_EQ(v, 0.0f) << "value " << i << " (bin " << i % 9 << ")";
    }
  }
  EXPECT_GT(in_bin4, 0.0);
}

TEST(HogTest, VerticalEdgeSplitsBetweenTheBinsAroundZeroDegrees) {
  // Left half 0, right half 200: gradients at 0 degrees, halfway between bins 0 (10 deg) and
  // 8 (170 deg, i.e. -10 deg): equal shares, nothing elsewhere.
  cv::Mat patch(64, 64, CV_8UC1, cv::Scalar(0));
  patch.colRange(32, 64).setTo(200);
  const cv::Mat row = Describe(HogDescriptor(Options(64)), patch);
  double bin0 = 0.0, bin8 = 0.0;
  for (int i = 0; i < row.cols; ++i) {
    const float v = row.at<float>(0, i);
    if (i % 9 == 0) {
      bin0 += v;
    } else if (i % 9 == 8) {
      bin8 += v;
    } else {
      EXPECT_EQ(v, 0.0f) << "value " << i << " (bin " << i % 9 << ")";
    }
  }
  EXPECT_GT(bin0, 0.0);
  EXPECT_NEAR(bin0, bin8, 1e-3 * bin0);
}

}  // namespace
}  // namespace openable
