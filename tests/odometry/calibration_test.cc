// ReadKittiCalibration (OpenABLE/odometry/calibration.h): the real calib.txt of KITTI 00, with
// values worked out by hand, and malformed files.
#include "OpenABLE/odometry/calibration.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/test_support.h"

namespace openable::odometry {
namespace {

const char kP0[] =
    "P0: 7.188560000000e+02 0 6.071928000000e+02 0 0 7.188560000000e+02 "
    "1.852157000000e+02 0 0 0 1 0\n";
const char kP1[] =
    "P1: 7.188560000000e+02 0 6.071928000000e+02 -3.861448000000e+02 0 "
    "7.188560000000e+02 1.852157000000e+02 0 0 0 1 0\n";

TEST(ReadKittiCalibration, HalvesTheRealKitti00Calibration) {
  const std::string path = testing::DatasetsDir() + "/kitti00_first1700/calib.txt";
  OPENABLE_REQUIRE_PATH(path);
  const KittiCalibration c = ReadKittiCalibration(path, 0.5);
  // By hand from the file: P0 = [718.856 0 607.1928 0; 0 718.856 185.2157 0; ...],
  // P1(0,3) = -386.1448.
  EXPECT_NEAR(c.left.fx, 359.428, 1e-9);
  EXPECT_NEAR(c.left.fy, 359.428, 1e-9);
  EXPECT_NEAR(c.left.cx, 303.5964, 1e-9);
  EXPECT_NEAR(c.left.cy, 92.60785, 1e-9);
  EXPECT_NEAR(c.baseline, 0.537165, 1e-6);  // 386.1448 / 718.856
  const cv::Matx33d K = c.left.K();
  EXPECT_EQ(K(0, 1), 0.0);
  EXPECT_EQ(K(0, 2), c.left.cx);
  EXPECT_EQ(K(2, 2), 1.0);
  // The baseline does not depend on the scale; the intrinsics do.
  const KittiCalibration full = ReadKittiCalibration(path, 1.0);
  EXPECT_NEAR(full.left.fx, 718.856, 1e-9);
  EXPECT_NEAR(full.baseline, c.baseline, 1e-12);
}

TEST(ReadKittiCalibration, ReadsAWrittenFileAndIgnoresOtherMatrices) {
  const std::string path = testing::TempDir() + "/calib.txt";
  testing::WriteBytes(path, std::string(kP0) + kP1 + "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  const KittiCalibration c = ReadKittiCalibration(path, 1.0);
  EXPECT_DOUBLE_EQ(c.left.fx, 718.856);
  EXPECT_NEAR(c.baseline, 0.537165, 1e-6);
}

TEST(ReadKittiCalibration, RejectsMalformedFilesWithFileAndLine) {
  const std::string dir = testing::TempDir();
  const std::string missing_p1 = dir + "/missing_p1.txt";
  testing::WriteBytes(missing_p1, kP0);
  testing::ExpectInputError([&] { ReadKittiCalibration(missing_p1, 0.5); },
                            {testing::Q(missing_p1) + ":1", "no P1"});

  const std::string short_line = dir + "/short.txt";
  testing::WriteBytes(short_line, std::string(kP0) + "P1: 1 2 3\n");
  testing::ExpectInputError([&] { ReadKittiCalibration(short_line, 0.5); },
                            {testing::Q(short_line) + ":2", "3 numbers, expected 12"});

  const std::string not_number = dir + "/nan.txt";
  testing::WriteBytes(not_number, std::string(kP0) + "P1: 1 2 3 4 5 6 7 8 9 10 11 x\n");
  testing::ExpectInputError([&] { ReadKittiCalibration(not_number, 0.5); },
                            {testing::Q(not_number) + ":2", "\"x\" is not a finite number"});

  const std::string no_colon = dir + "/colon.txt";
  testing::WriteBytes(no_colon, "P0 1 2 3\n");
  testing::ExpectInputError([&] { ReadKittiCalibration(no_colon, 0.5); },
                            {testing::Q(no_colon) + ":1", "expected \"<name>: 12 numbers\""});

  const std::string left_baseline = dir + "/left.txt";  // P1(0,3) > 0: camera 1 on the left
  testing::WriteBytes(left_baseline, std::string(kP0) + "P1: 700 0 600 386 0 700 185 0 0 0 1 0\n");
  testing::ExpectInputError([&] { ReadKittiCalibration(left_baseline, 0.5); },
                            {testing::Q(left_baseline) + ":2", "baseline"});

  const std::string absent = dir + "/absent.txt";
  testing::ExpectInputError([&] { ReadKittiCalibration(absent, 0.5); },
                            {testing::Q(absent), "does not exist"});
  testing::ExpectInputError([&] { ReadKittiCalibration(missing_p1, 0.0); }, {"scale"});
}

}  // namespace
}  // namespace openable::odometry
