// The stereo calibration loader (OpenABLE/stereo/calibration.h) and the EuRoC conversion of
// the test helper (tests/tools/euroc_calibration.h).
#include "OpenABLE/stereo/calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "tests/test_support.h"
#include "tests/tools/euroc_calibration.h"

namespace openable {
namespace {

using testing::ExpectInputError;

std::string EurocDir() { return testing::DatasetsDir() + "/euroc_stereo_pairs"; }

// One opencv-matrix node as OpenCV writes it.
std::string MatrixNode(const std::string& key, int rows, int cols, const std::string& data) {
  return key + ": !!opencv-matrix\n   rows: " + std::to_string(rows) +
         "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ " + data + " ]\n";
}

// A valid calibration (EuRoC-like numbers), each node replaceable or removable ("" removes).
std::string CalibrationText(const std::map<std::string, std::string>& replace = {}) {
  std::map<std::string, std::string> nodes = {
      {"ML", MatrixNode("ML", 3, 3, "458.654, 0., 367.215, 0., 457.296, 248.375, 0., 0., 1.")},
      {"MR", MatrixNode("MR", 3, 3, "457.587, 0., 379.999, 0., 456.134, 255.238, 0., 0., 1.")},
      {"DL", MatrixNode("DL", 5, 1, "-0.2834, 0.0740, 0.0002, 0.00002, 0.")},
      {"DR", MatrixNode("DR", 5, 1, "-0.2837, 0.0745, -0.0001, -0.00004, 0.")},
      {"R", MatrixNode("R", 3, 3, "1., 0., 0., 0., 1., 0., 0., 0., 1.")},
      {"T", MatrixNode("T", 3, 1, "-0.110, 0., 0.")},
      {"colormap", "colormap: 2\n"},
      {"use_log", "use_log: 1\n"}};
  for (const auto& [key, text] : replace) nodes[key] = text;
  std::string out = "%YAML:1.0\n---\n";
  for (const char* key : {"ML", "MR", "DL", "DR", "R", "T", "colormap", "use_log"})
    out += nodes[key];
  return out;
}

std::string Write(const std::string& text, const std::string& name = "calib.yaml") {
  const std::string path = testing::TempDir() + "/" + name;
  testing::WriteBytes(path, text);
  return path;
}

TEST(StereoCalibration, LoadsEveryKey) {
  const StereoCalibration c = LoadStereoCalibration(Write(CalibrationText()));
  EXPECT_DOUBLE_EQ(c.left_camera(0, 0), 458.654);
  EXPECT_DOUBLE_EQ(c.left_camera(1, 2), 248.375);
  EXPECT_DOUBLE_EQ(c.right_camera(0, 2), 379.999);
  EXPECT_DOUBLE_EQ(c.left_distortion[0], -0.2834);
  EXPECT_DOUBLE_EQ(c.right_distortion[3], -0.00004);
  EXPECT_DOUBLE_EQ(c.rotation(1, 1), 1.0);
  EXPECT_DOUBLE_EQ(c.translation[0], -0.110);
  EXPECT_EQ(c.colormap, 2);
  EXPECT_EQ(c.use_log, 1);
}

TEST(StereoCalibration, AcceptsRowVectorsAndDefaultsTheRenderingKeys) {
  const StereoCalibration c = LoadStereoCalibration(
      Write(CalibrationText({{"DL", MatrixNode("DL", 1, 5, "0.1, 0.2, 0.3, 0.4, 0.5")},
                             {"T", MatrixNode("T", 1, 3, "-537.2, 1., 2.")},
                             {"colormap", ""},
                             {"use_log", ""}})));
  EXPECT_DOUBLE_EQ(c.left_distortion[4], 0.5);
  EXPECT_DOUBLE_EQ(c.translation[0], -537.2);
  EXPECT_DOUBLE_EQ(c.translation[2], 2.0);
  EXPECT_EQ(c.colormap, -1);
  EXPECT_EQ(c.use_log, 0);
}

TEST(StereoCalibration, MissingFile) {
  const std::string path = testing::TempDir() + "/none.yaml";
  ExpectInputError([&] { LoadStereoCalibration(path); }, {testing::Q(path), "does not exist"});
}

TEST(StereoCalibration, NotYaml) {
  const std::string text = Write("ML = [1 2 3]\nMR = 4\n");
  ExpectInputError([&] { LoadStereoCalibration(text); },
                   {testing::Q(text), "\"ML = [1 2 3]\"", "%YAML:1.0"});
  const std::string binary = Write(std::string("\x89PNG\r\n\x1a\n\0\0", 10), "calib.png");
  ExpectInputError([&] { LoadStereoCalibration(binary); }, {testing::Q(binary), "%YAML:1.0"});
  const std::string broken = Write("%YAML:1.0\nML: [1, 2\nMR: {\n");
  ExpectInputError([&] { LoadStereoCalibration(broken); },
                   {testing::Q(broken), "not valid OpenCV YAML"});
}

TEST(StereoCalibration, MissingKey) {
  for (const char* key : {"ML", "MR", "DL", "DR", "R", "T"}) {
    const std::string path = Write(CalibrationText({{key, ""}}));
    ExpectInputError([&] { LoadStereoCalibration(path); },
                     {testing::Q(path), std::string(": ") + key + ": missing; expected a "});
  }
}

TEST(StereoCalibration, WrongMatrixSize) {
  const std::string ml =
      Write(CalibrationText({{"ML", MatrixNode("ML", 3, 2, "1, 0, 0, 1, 0, 0")}}));
  ExpectInputError([&] { LoadStereoCalibration(ml); },
                   {testing::Q(ml), "ML: a 3x2 matrix; expected a 3x3 opencv-matrix"});
  const std::string dr = Write(CalibrationText({{"DR", MatrixNode("DR", 4, 1, "0, 0, 0, 0")}}));
  ExpectInputError([&] { LoadStereoCalibration(dr); },
                   {testing::Q(dr), "DR: a 4x1 matrix; expected a 5x1 (or 1x5)"});
  const std::string t = Write(CalibrationText({{"T", MatrixNode("T", 2, 2, "1, 0, 0, 1")}}));
  ExpectInputError([&] { LoadStereoCalibration(t); }, {"T: a 2x2 matrix; expected a 3x1"});
  const std::string scalar = Write(CalibrationText({{"R", "R: 1.0\n"}}));
  ExpectInputError([&] { LoadStereoCalibration(scalar); }, {"R: not a matrix; expected a 3x3"});
}

TEST(StereoCalibration, NonFiniteValue) {
  const std::string path = Write(CalibrationText(
      {{"MR", MatrixNode("MR", 3, 3, "457.5, 0., .Nan, 0., 456.1, 255.2, 0., 0., 1.")}}));
  ExpectInputError([&] { LoadStereoCalibration(path); },
                   {testing::Q(path), "MR: element (0,2) is nan; expected finite numbers"});
  const std::string inf = Write(CalibrationText({{"T", MatrixNode("T", 3, 1, "-.Inf, 0., 0.")}}));
  ExpectInputError([&] { LoadStereoCalibration(inf); }, {"T: element (0,0) is -inf"});
}

TEST(StereoCalibration, NonPositiveFocalLength) {
  const std::string path = Write(CalibrationText(
      {{"ML", MatrixNode("ML", 3, 3, "-458.6, 0., 367.2, 0., 457.3, 248.4, 0., 0., 1.")}}));
  ExpectInputError(
      [&] { LoadStereoCalibration(path); },
      {testing::Q(path), "ML: focal length fx = -458.6, fy = 457.3; expected both > 0"});
  const std::string zero = Write(CalibrationText(
      {{"MR", MatrixNode("MR", 3, 3, "458.6, 0., 367.2, 0., 0., 248.4, 0., 0., 1.")}}));
  ExpectInputError([&] { LoadStereoCalibration(zero); }, {"MR: focal length", "fy = 0;"});
}

TEST(StereoCalibration, OtherBadValues) {
  const std::string rot =
      Write(CalibrationText({{"R", MatrixNode("R", 3, 3, "1, 0, 0, 0, 2, 0, 0, 0, 1")}}));
  ExpectInputError([&] { LoadStereoCalibration(rot); }, {"R: not a rotation", "det = 2"});
  const std::string t = Write(CalibrationText({{"T", MatrixNode("T", 3, 1, "0, 0, 0")}}));
  ExpectInputError([&] { LoadStereoCalibration(t); }, {"T: (0, 0, 0); expected the non-zero"});
  const std::string map = Write(CalibrationText({{"colormap", "colormap: 40\n"}}));
  ExpectInputError([&] { LoadStereoCalibration(map); },
                   {"colormap: 40 is out of range; expected an integer in [-1, 21]"});
  const std::string bottom = Write(CalibrationText(
      {{"ML", MatrixNode("ML", 3, 3, "458.6, 0., 367.2, 0., 457.3, 248.4, 0., 0., 0.")}}));
  ExpectInputError([&] { LoadStereoCalibration(bottom); }, {"ML: rows 2-3", "0 0 1"});
}

TEST(StereoCalibration, PrincipalPointsMustLieInTheMiddleOfTheImages) {
  const StereoCalibration c = LoadStereoCalibration(Write(CalibrationText()));
  EXPECT_NO_THROW(CheckCalibrationFits(c, cv::Size(752, 480), "left/0.png"));
  // Half-size images: (367.2, 248.4) is beyond 3/4 of 376 columns (282).
  ExpectInputError([&] { CheckCalibrationFits(c, cv::Size(376, 240), "left/0.png"); },
                   {"does not fit the images", "ML principal point (367.215, 248.375)",
                    "376x240 image \"left/0.png\"", "about 734x497", testing::Q(c.path)});
  // Full-size KITTI intrinsics on the half-size frames: inside the image, but not in its
  // middle half (cx 607 > 465).
  const StereoCalibration kitti = LoadStereoCalibration(Write(CalibrationText(
      {{"ML", MatrixNode("ML", 3, 3, "718.856, 0., 607.1928, 0., 718.856, 185.2157, 0., 0., 1.")},
       {"MR",
        MatrixNode("MR", 3, 3, "718.856, 0., 607.1928, 0., 718.856, 185.2157, 0., 0., 1.")}})));
  EXPECT_NO_THROW(CheckCalibrationFits(kitti, cv::Size(1241, 376), "full.png"));
  ExpectInputError([&] { CheckCalibrationFits(kitti, cv::Size(620, 188), "half.png"); },
                   {"ML principal point (607.193, 185.216)", "620x188", "about 1214x370"});
  // Only the right camera off.
  const StereoCalibration right = LoadStereoCalibration(Write(CalibrationText(
      {{"MR", MatrixNode("MR", 3, 3, "457.5, 0., 700., 0., 456.1, 255.2, 0., 0., 1.")}})));
  ExpectInputError([&] { CheckCalibrationFits(right, cv::Size(752, 480), "l.png"); },
                   {"MR principal point (700, 255.2)", "752x480"});
}

TEST(EurocConversion, GivesTheBaselineAlongXAndANearIdentityRotation) {
  OPENABLE_REQUIRE_PATH(EurocDir());
  testing::EurocCamera left, right;
  ASSERT_TRUE(testing::ReadEurocCamera(EurocDir() + "/sensorLeft.yaml", left));
  ASSERT_TRUE(testing::ReadEurocCamera(EurocDir() + "/sensorRight.yaml", right));
  const testing::ConvertedCalibration c = testing::ConvertEuroc(left, right);

  // Independent of the composition: the distance between the two camera centres, read
  // straight from the last columns of the two T_BS, is the baseline.
  const cv::Vec3d centre_left(left.body_from_sensor(0, 3), left.body_from_sensor(1, 3),
                              left.body_from_sensor(2, 3));
  const cv::Vec3d centre_right(right.body_from_sensor(0, 3), right.body_from_sensor(1, 3),
                               right.body_from_sensor(2, 3));
  const double baseline = cv::norm(centre_right - centre_left);
  EXPECT_NEAR(baseline, 0.110, 0.005);
  EXPECT_NEAR(cv::norm(c.t), baseline, 1e-9);
  // The right camera sits to the right (+x) of the left one, so a left-frame point has a
  // smaller x in the right frame: T ~ (-0.11, 0, 0).
  EXPECT_LT(c.t[0], -0.105);
  EXPECT_LT(std::hypot(c.t[1], c.t[2]), 0.005);
  // R near identity: rotation angle below 1 degree (EuRoC's cameras are nearly parallel).
  const double cos_angle = (cv::trace(c.r) - 1.0) / 2.0;
  EXPECT_GT(cos_angle, std::cos(1.0 * CV_PI / 180.0));
  EXPECT_LT(cv::norm(c.r.t() * c.r - cv::Matx33d::eye(), cv::NORM_INF), 1e-6);
  EXPECT_DOUBLE_EQ(c.ml(0, 0), 458.654);
  EXPECT_DOUBLE_EQ(c.mr(1, 2), 255.238);
  EXPECT_DOUBLE_EQ(c.dl[0], -0.28340811);
  EXPECT_DOUBLE_EQ(c.dr[4], 0.0);

  // The written file loads back through the project's loader unchanged.
  const std::string path = testing::TempDir() + "/euroc.yaml";
  ASSERT_TRUE(testing::WriteEurocCalibration(EurocDir(), path));
  const StereoCalibration loaded = LoadStereoCalibration(path);
  EXPECT_LT(cv::norm(loaded.translation - c.t), 1e-12);
  EXPECT_LT(cv::norm(loaded.rotation - c.r), 1e-12);
  EXPECT_EQ(loaded.left_camera, c.ml);
  EXPECT_NO_THROW(CheckCalibrationFits(loaded, cv::Size(752, 480), "left_img_0.png"));
}

}  // namespace
}  // namespace openable
