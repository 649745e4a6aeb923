// Helpers of the stereo tests: the EuRoC pairs of ../shared/datasets and synthetic pairs.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "OpenABLE/stereo/calibration.h"
#include "tests/test_support.h"
#include "tests/tools/euroc_calibration.h"

namespace openable::stereo_test {

inline std::string EurocDir() { return testing::DatasetsDir() + "/euroc_stereo_pairs"; }

// The EuRoC calibration converted (tests/tools/euroc_calibration.h) into a temporary file.
inline std::string EurocCalibrationFile() {
  const std::string path = testing::TempDir() + "/euroc_calibration.yaml";
  if (!std::filesystem::exists(path)) testing::WriteEurocCalibration(EurocDir(), path);
  return path;
}

inline cv::Mat ReadGray(const std::string& path) { return cv::imread(path, cv::IMREAD_GRAYSCALE); }
inline cv::Mat EurocLeft(int i) {
  return ReadGray(EurocDir() + "/left_img_" + std::to_string(i) + ".png");
}
inline cv::Mat EurocRight(int i) {
  return ReadGray(EurocDir() + "/right_img_" + std::to_string(i) + ".png");
}

// Copies pairs [0, n) of EuRoC into <dir>/left and <dir>/right (file names 0.png ...).
inline void CopyEurocPairs(const std::string& dir, int n) {
  namespace fs = std::filesystem;
  fs::create_directories(dir + "/left");
  fs::create_directories(dir + "/right");
  for (int i = 0; i < n; ++i) {
    fs::copy_file(EurocDir() + "/left_img_" + std::to_string(i) + ".png",
                  dir + "/left/" + std::to_string(i) + ".png");
    fs::copy_file(EurocDir() + "/right_img_" + std::to_string(i) + ".png",
                  dir + "/right/" + std::to_string(i) + ".png");
  }
}

// A textured 8-bit image (blurred noise at two scales), fixed seed.
inline cv::Mat Texture(const cv::Size& size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(size, CV_32F), fine(size, CV_32F);
  rng.fill(coarse, cv::RNG::NORMAL, 0.0, 1.0);
  rng.fill(fine, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(coarse, coarse, cv::Size(0, 0), 6.0);
  cv::GaussianBlur(fine, fine, cv::Size(0, 0), 1.0);
  cv::normalize(coarse, coarse, -1.0, 1.0, cv::NORM_MINMAX);
  cv::normalize(fine, fine, -1.0, 1.0, cv::NORM_MINMAX);
  cv::Mat field = 128.0 + 60.0 * coarse + 50.0 * fine, out;
  field.convertTo(out, CV_8U);
  return out;
}

// An ideal rectified calibration for images of `size`: identical pinhole cameras (focal f,
// centred principal point), no distortion, R = I, T = (-baseline, 0, 0).
inline std::string IdealCalibrationFile(const cv::Size& size, double f = 100.0,
                                        double baseline = 0.1) {
  const std::string path = testing::TempDir() + "/ideal_calibration.yaml";
  testing::ConvertedCalibration c;
  c.ml = c.mr = cv::Matx33d(f, 0, (size.width - 1) / 2.0, 0, f, (size.height - 1) / 2.0, 0, 0, 1);
  c.dl = c.dr = cv::Vec<double, 5>::all(0.0);
  c.r = cv::Matx33d::eye();
  c.t = cv::Vec3d(-baseline, 0, 0);
  testing::WriteCalibrationFile(c, path);
  return path;
}

}  // namespace openable::stereo_test
