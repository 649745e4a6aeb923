// The stereo frame source (OpenABLE/stereo/stereo_source.h), and D-LDB over its frames.
#include "OpenABLE/stereo/stereo_source.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "OpenABLE/describe/describe.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/stereo/rectification.h"
#include "descriptors/registry.h"
#include "tests/stereo/stereo_test_util.h"

namespace openable {
namespace {

using namespace stereo_test;  // NOLINT: this file's vocabulary
using testing::ExpectInputError;
namespace fs = std::filesystem;

// <dir>/left and <dir>/right with `left` and `right` synthetic 160x120 images.
std::string SyntheticFolders(int left, int right, cv::Size right_size = cv::Size(160, 120)) {
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/left");
  fs::create_directories(dir + "/right");
  for (int i = 0; i < left; ++i)
    cv::imwrite(dir + "/left/f" + std::to_string(i) + ".png", Texture(cv::Size(160, 120), i));
  for (int i = 0; i < right; ++i)
    cv::imwrite(dir + "/right/f" + std::to_string(i) + ".png", Texture(right_size, 100 + i));
  return dir;
}

int Hamming(const cv::Mat& a, const cv::Mat& b) {
  int bits = 0;
  for (int i = 0; i < a.cols; ++i) {
    unsigned x = a.at<std::uint8_t>(0, i) ^ b.at<std::uint8_t>(0, i);
    for (; x != 0; x >>= 1) bits += static_cast<int>(x & 1u);
  }
  return bits;
}

TEST(StereoSource, FoldersOfDifferentLengthsAreAnError) {
  const std::string dir = SyntheticFolders(3, 4);
  const StereoCalibration c = LoadStereoCalibration(IdealCalibrationFile(cv::Size(160, 120)));
  ExpectInputError(
      [&] { OpenStereoFolders(dir + "/left", dir + "/right", "png", 0, -1, c); },
      {"Images_path_left/Images_path_right", testing::Q(dir + "/left") + " holds 3 images",
       testing::Q(dir + "/right") + " holds 4", "matched by position"});
}

TEST(StereoSource, LeftAndRightOfDifferentSizesNameTheFrame) {
  const std::string dir = SyntheticFolders(2, 2, cv::Size(150, 120));
  const StereoCalibration c = LoadStereoCalibration(IdealCalibrationFile(cv::Size(160, 120)));
  const auto source = OpenStereoFolders(dir + "/left", dir + "/right", "png", 0, -1, c);
  ExpectInputError([&] { source->Read(1); },
                   {"stereo pair 1", testing::Q(dir + "/left/f1.png") + " is 160x120",
                    testing::Q(dir + "/right/f1.png") + " is 150x120"});
}

TEST(StereoSource, MissingFolderAndUnfittingCalibration) {
  const std::string dir = SyntheticFolders(2, 2);
  const StereoCalibration c = LoadStereoCalibration(IdealCalibrationFile(cv::Size(160, 120)));
  ExpectInputError([&] { OpenStereoFolders(dir + "/nope", dir + "/right", "png", 0, -1, c); },
                   {"Images_path_left: ", "nope"});
  ExpectInputError([&] { OpenStereoFolders(dir + "/left", dir + "/nope", "png", 0, -1, c); },
                   {"Images_path_right: ", "nope"});
  // A calibration for 640x480 images: principal point (319.5, 239.5) outside 160x120.
  const StereoCalibration big = LoadStereoCalibration(IdealCalibrationFile(cv::Size(640, 480)));
  ExpectInputError([&] { OpenStereoFolders(dir + "/left", dir + "/right", "png", 0, -1, big); },
                   {"Calibration_path: ", "does not fit the images", "160x120", "about 639x479",
                    testing::Q(dir + "/left/f0.png")});
}

TEST(StereoSource, FramesHoldTheRectifiedLeftImageAndTheDisparity) {
  const std::string dir = SyntheticFolders(3, 3);
  const StereoCalibration c = LoadStereoCalibration(IdealCalibrationFile(cv::Size(160, 120)));
  const auto source = OpenStereoFolders(dir + "/left", dir + "/right", "png", 1, -1, c);
  ASSERT_EQ(source->Size(), 2);
  EXPECT_TRUE(source->ParallelReads());
  EXPECT_EQ(source->FrameName(0), dir + "/left/f1.png");
  const cv::Mat frame = source->Read(0);
  ASSERT_EQ(frame.type(), CV_32FC2);
  ASSERT_EQ(frame.size(), cv::Size(160, 120));
  cv::Mat channels[2];
  cv::split(frame, channels);
  // Ideal cameras: channel 0 is the left image itself (remap within 1 grey level).
  cv::Mat left = cv::imread(dir + "/left/f1.png", cv::IMREAD_GRAYSCALE), left_f;
  left.convertTo(left_f, CV_32F, 1.0 / 255.0);
  EXPECT_LE(cv::norm(channels[0], left_f, cv::NORM_INF), 1.0 / 255.0 + 1e-6);
  double lo, hi;
  cv::minMaxLoc(channels[1], &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_LT(hi, 1.0);
  EXPECT_EQ(ToGray8(frame).type(), CV_8UC1);
  EXPECT_EQ(ToGrayDisparity8(frame).type(), CV_8UC2);

  // Without disparity (descriptors other than D-LDB): the same channel 0, channel 1 zero.
  StereoSourceOptions no_disparity;
  no_disparity.compute_disparity = false;
  const auto grey_only =
      OpenStereoFolders(dir + "/left", dir + "/right", "png", 1, -1, c, no_disparity);
  cv::Mat g[2];
  cv::split(grey_only->Read(0), g);
  EXPECT_EQ(cv::norm(g[0], channels[0], cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(g[1]), 0);
}

// The four EuRoC pairs as a stereo source, described with D-LDB (global, 64 x 64).
class EurocDldb : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(EurocDir())) GTEST_SKIP() << "dataset absent: " << EurocDir();
    dir_ = testing::TempDir();
    CopyEurocPairs(dir_, 4);
    calibration_ = LoadStereoCalibration(EurocCalibrationFile());
    source_ = OpenStereoFolders(dir_ + "/left", dir_ + "/right", "png", 0, -1, calibration_);
  }
  std::string dir_;
  StereoCalibration calibration_;
  std::unique_ptr<FrameSource> source_;
};

TEST_F(EurocDldb, RevisitIsCloserThanOtherPlaces) {
  // Every LDB test (Ldb_bits 1386) on both halves. Pair 1 sees pair 0's place from ~0.4 m away
  // and turned (see gt_poses.txt): with the default 256-bit random subset the margin is one
  // bit either way (0-1: 187, 0-2: 186, docs/benchmarks.md), within the subset's sampling
  // noise, so the full string is the setting whose ordering means something here.
  DescriptorOptions o;
  o.ldb_bits = 1386;
  const auto dldb = CreateDescriptor("D-LDB", o);
  const FrameDescriber describer(*dldb, DescriptionType::kGlobal);
  DescribeOptions options;
  const DescribedSequence seq = DescribeSequence(*source_, describer, options);
  ASSERT_EQ(seq.rows.rows, 4);
  ASSERT_EQ(seq.rows.cols, 2 * 174);
  const int revisit = Hamming(seq.rows.row(0), seq.rows.row(1));
  const int other2 = Hamming(seq.rows.row(0), seq.rows.row(2));
  const int other3 = Hamming(seq.rows.row(0), seq.rows.row(3));
  std::cout << "D-LDB Hamming (of 2 x 1386 bits): pair 0-1 (revisit) " << revisit << ", 0-2 "
            << other2 << ", 0-3 " << other3 << ", 1-2 " << Hamming(seq.rows.row(1), seq.rows.row(2))
            << ", 1-3 " << Hamming(seq.rows.row(1), seq.rows.row(3)) << ", 2-3 (0.5 s apart) "
            << Hamming(seq.rows.row(2), seq.rows.row(3)) << "\n";
  EXPECT_LT(revisit, other2);
  EXPECT_LT(revisit, other3);
  // Pair 1 is the earlier visit of the same place: it too is farther from 2 and 3.
  EXPECT_LT(revisit, Hamming(seq.rows.row(1), seq.rows.row(2)));
  EXPECT_LT(revisit, Hamming(seq.rows.row(1), seq.rows.row(3)));
}

TEST_F(EurocDldb, FirstHalfIsLdbOfTheRectifiedLeftImage) {
  DescriptorOptions o;
  const auto dldb = CreateDescriptor("D-LDB", o);
  const auto ldb = CreateDescriptor("LDB", o);
  ASSERT_EQ(dldb->Width(), 2 * ldb->Width());
  // The rectified left image made here from the calibration, not taken from the source.
  const StereoRectifier rectifier(calibration_, cv::Size(752, 480));
  for (const DescriptionType type : {DescriptionType::kGlobal, DescriptionType::kGrid}) {
    const FrameDescriber d_dldb(*dldb, type, 2, 2), d_ldb(*ldb, type, 2, 2);
    for (int i = 0; i < 4; ++i) {
      const cv::Mat frame = source_->Read(i);
      cv::Mat row(1, d_dldb.RowWidth(), CV_8U);
      d_dldb.Describe(ToGrayDisparity8(frame), row);
      cv::Mat left_r, unused;
      rectifier.Rectify(EurocLeft(i), cv::Mat(), left_r, unused);
      cv::Mat expected(1, d_ldb.RowWidth(), CV_8U);
      d_ldb.Describe(left_r, expected);
      // Each cell: LDB(grey cell) ++ LDB(disparity cell).
      const int w = ldb->Width(), cells = type == DescriptionType::kGrid ? 4 : 1;
      ASSERT_EQ(row.cols, 2 * w * cells);
      for (int cell = 0; cell < cells; ++cell) {
        const cv::Mat got = row.colRange(2 * w * cell, 2 * w * cell + w);
        const cv::Mat want = expected.colRange(w * cell, w * (cell + 1));
        EXPECT_EQ(cv::norm(got, want, cv::NORM_HAMMING), 0.0) << "pair " << i << " cell " << cell;
      }
      // The disparity half is not a copy of the grey half.
      EXPECT_GT(cv::norm(row.colRange(0, w), row.colRange(w, 2 * w), cv::NORM_HAMMING), 0.0);
    }
  }
}

}  // namespace
}  // namespace openable
