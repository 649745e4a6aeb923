// End-to-end runs of Test_OpenABLE with a stereo camera (Camera_type 1) on the real EuRoC
// pairs, and its stereo input errors (one line, exit 1).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"
#include "tests/tools/euroc_calibration.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

std::string EurocDir() { return testing::DatasetsDir() + "/euroc_stereo_pairs"; }

bool OneLine(const std::string& s) { return !s.empty() && s.find('\n') == s.size() - 1; }

// <dir>/left, <dir>/right with EuRoC pairs [0, left) and [0, right), the calibration converted
// into <dir>/calibration.yaml, and a Config.txt for them.
std::string StereoRun(const std::string& dir, int left, int right, const std::string& extra = "") {
  fs::create_directories(dir + "/left");
  fs::create_directories(dir + "/right");
  for (int i = 0; i < left; ++i)
    fs::copy_file(EurocDir() + "/left_img_" + std::to_string(i) + ".png",
                  dir + "/left/left_img_" + std::to_string(i) + ".png");
  for (int i = 0; i < right; ++i)
    fs::copy_file(EurocDir() + "/right_img_" + std::to_string(i) + ".png",
                  dir + "/right/right_img_" + std::to_string(i) + ".png");
  EXPECT_TRUE(testing::WriteEurocCalibration(EurocDir(), dir + "/calibration.yaml"));
  const std::string path = dir + "/Config.txt";
  std::ofstream(path) << "%YAML:1.0\n"
                      << "Frame_mode: 0\n"
                      << "Camera_type: 1\n"
                      << "Images_path_left: \"left\"\n"
                      << "Images_path_right: \"right\"\n"
                      << "Calibration_path: \"calibration.yaml\"\n"
                      << "Images_format: png\n"
                      << "Npy_name: \"out/matrix.npy\"\n"
                      << "Txt_name: \"out/matrix.txt\"\n"
                      << "Image_descriptor: D-LDB\n"
                      << "Ldb_bits: 1386\n"
                      << extra;
  return path;
}

TEST(StereoRun, DldbOnTheEurocPairsWritesA4x4Matrix) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(), {StereoRun(dir, 4, 4)}, dir);
  ASSERT_EQ(o.status, 0) << o.err << o.out;
  EXPECT_NE(o.err.find("stereo pairs (rectify, SGBM, D-LDB)"), std::string::npos) << o.err;
  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 4);
  ASSERT_EQ(m.cols, 4);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(m(i, i), 0.0f);
  EXPECT_EQ(cv::norm(m, m.t(), cv::NORM_INF), 0.0);
  // The revisit (0, 1) is the closest pair after the near-duplicate (2, 3), and the closest
  // match of frame 0 (the matrix is D-LDB Hamming / max: 898, 992, 1101 in
  // tests/stereo/stereo_source_test.cc).
  EXPECT_LT(m(0, 1), m(0, 2));
  EXPECT_LT(m(0, 1), m(0, 3));
  EXPECT_LT(m(2, 3), m(0, 1));
  EXPECT_FLOAT_EQ(m(0, 3), 1.0f);
}

TEST(StereoRun, OtherDescriptorsDescribeTheRectifiedLeftImage) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {StereoRun(dir, 4, 4), "--set", "Image_descriptor=ORB"}, dir);
  ASSERT_EQ(o.status, 0) << o.err << o.out;
  EXPECT_NE(o.err.find("stereo pairs (rectify, ORB)"), std::string::npos) << o.err;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 4);
}

TEST(StereoRun, FoldersOfDifferentLengthsAreOneLineAndExit1) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(), {StereoRun(dir, 4, 3)}, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("\"left\" holds 4 images but folder \"right\" holds 3"), std::string::npos)
      << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

TEST(StereoRun, BadCalibrationIsOneLineAndExit1) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  const std::string dir = testing::TempDir();
  const std::string config = StereoRun(dir, 2, 2);
  testing::WriteBytes(dir + "/broken.yaml", "%YAML:1.0\nML: 3\n");
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {config, "--set", "Calibration_path=broken.yaml"}, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("Calibration_path: calibration \"broken.yaml\": ML: not a matrix"),
            std::string::npos)
      << o.err;
}

TEST(StereoRun, DldbWithoutStereoIsOneLineAndExit1) {
  const std::string dir = testing::TempDir();
  const std::string path = dir + "/Config.txt";
  std::ofstream(path) << "Images_path: \"" << testing::SampleDir() << "/summer\"\n"
                      << "Image_descriptor: D-LDB\n";
  const Outcome o = RunProgram(testing::TestOpenableExe(), {path}, dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("Image_descriptor: D-LDB needs Camera_type 1 (stereo)"), std::string::npos)
      << o.err;
}

}  // namespace
}  // namespace openable
