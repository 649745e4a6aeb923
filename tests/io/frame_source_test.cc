#include "OpenABLE/io/frame_source.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/io/module_api.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;
using openable::testing::ExpectInputError;
using openable::testing::Q;
using openable::testing::TempDir;
using openable::testing::WriteBytes;

// ---------------------------------------------------------------------------------------------
// Helpers

// Writes an image with OpenImageIO from interleaved pixels of `type` (alpha kept as given).
template <typename T>
void WriteOiio(const std::string& path, int width, int height, int channels,
               const OIIO::TypeDesc& type, const std::vector<T>& pixels, int alpha_channel = -1) {
  ASSERT_EQ(pixels.size(), static_cast<std::size_t>(width) * height * channels);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(width, height, channels, type);
  spec.alpha_channel = alpha_channel;
  spec.attribute("oiio:UnassociatedAlpha", 1);
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(type, pixels.data())) << out->geterror();
  ASSERT_TRUE(out->close()) << out->geterror();
}

std::string ReadBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// Keeps the first half of the bytes of a file.
void TruncateToHalf(const std::string& path) {
  const std::string bytes = ReadBytes(path);
  ASSERT_GT(bytes.size(), 200u);
  fs::resize_file(path, bytes.size() / 2);
}

cv::Mat Noise(int width, int height, int type, std::uint64_t seed) {
  cv::Mat m(height, width, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

// ---------------------------------------------------------------------------------------------
// NaturalLess

TEST(NaturalLess, DigitRunsCompareByValue) {
  EXPECT_TRUE(NaturalLess("img2", "img10"));
  EXPECT_FALSE(NaturalLess("img10", "img2"));
  EXPECT_TRUE(NaturalLess("frame_9.png", "frame_10.png"));
  EXPECT_FALSE(NaturalLess("frame_10.png", "frame_9.png"));
  EXPECT_TRUE(NaturalLess("img1.png", "img2.png"));
  EXPECT_TRUE(NaturalLess("x2y10", "x2y11"));
  EXPECT_TRUE(NaturalLess("x2y9z", "x10a"));
  EXPECT_TRUE(NaturalLess("000123", "124"));
  // Plain plain-text parts still compare character by character.
  EXPECT_TRUE(NaturalLess("abc", "abd"));
  EXPECT_TRUE(NaturalLess("a", "a1"));
  EXPECT_TRUE(NaturalLess("", "a"));
  EXPECT_FALSE(NaturalLess("", ""));
  EXPECT_FALSE(NaturalLess("img10", "img10"));
  // Digit runs sort between the characters below '0' and those above '9'.
  EXPECT_TRUE(NaturalLess("a-1", "a0"));
  EXPECT_TRUE(NaturalLess("a99", "a_1"));
}

TEST(NaturalLess, EqualValuesAreBrokenByPlainOrder) {
  // "a01" and "a1" have the same value: exactly one of them is first, always the same.
  EXPECT_TRUE(NaturalLess("a01", "a1"));
  EXPECT_FALSE(NaturalLess("a1", "a01"));
  EXPECT_TRUE(NaturalLess("a0", "a00"));
  EXPECT_FALSE(NaturalLess("a00", "a0"));
  // The value decides before the tie-break does.
  EXPECT_TRUE(NaturalLess("a1", "a02"));
  EXPECT_TRUE(NaturalLess("a01b", "a1c"));
  EXPECT_TRUE(NaturalLess("a1b", "a01c"));
}

TEST(NaturalLess, DigitRunsLongerThan64BitsDoNotOverflow) {
  const std::string nines20(20, '9');  // 99999999999999999999 > 2^64
  const std::string ten_pow_20 = "1" + std::string(20, '0');
  EXPECT_TRUE(NaturalLess("f" + nines20, "f" + ten_pow_20));
  EXPECT_FALSE(NaturalLess("f" + ten_pow_20, "f" + nines20));
  EXPECT_TRUE(NaturalLess("f" + ten_pow_20, "f1" + std::string(19, '0') + "1"));
  EXPECT_TRUE(NaturalLess("f" + std::string(30, '0') + "7", "f8"));
  EXPECT_TRUE(NaturalLess("f12345678901234567890123x", "f12345678901234567890124a"));
}

TEST(NaturalLess, SortsShuffledNamesIntoTheKnownOrder) {
  const std::vector<std::string> expected = {
      "",
      "a",
      "a-1",
      "a0",
      "a00",
      "a01",
      "a1",
      "a2",
      "a10",
      "a10b",
      "a11",
      "a_1",
      "b",
      "frame_9.png",
      "frame_10.png",
      "frame_100.png",
      "img1.png",
      "img2.png",
      "img10.png",
      "img12x3",
      "img12x20",
      "z1",
      "z99999999999999999999",
      "z0100000000000000000000",
      "z100000000000000000000",
      "z100000000000000000001",
  };
  std::mt19937 rng(12345);
  for (int round = 0; round < 20; ++round) {
    std::vector<std::string> names = expected;
    std::shuffle(names.begin(), names.end(), rng);
    std::sort(names.begin(), names.end(), NaturalLess);
    ASSERT_EQ(names, expected) << "round " << round;
  }
  // Strict total order on these names: irreflexive, exactly one of a<b, b<a, transitive.
  for (const auto& a : expected) {
    EXPECT_FALSE(NaturalLess(a, a)) << a;
    for (const auto& b : expected) {
      if (a != b) {
        EXPECT_NE(NaturalLess(a, b), NaturalLess(b, a)) << a << " / " << b;
      }
      for (const auto& c : expected) {
        if (NaturalLess(a, b) && NaturalLess(b, c)) {
          EXPECT_TRUE(NaturalLess(a, c)) << a << " < " << b << " < " << c;
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// ListImages

TEST(SupportedImageExtensions, ListsTheDocumentedFormats) {
  const std::vector<std::string> expected = {"png", "jpg", "jpeg", "tif", "tiff",
                                             "pgm", "ppm", "pnm",  "pbm", "bmp"};
  EXPECT_EQ(SupportedImageExtensions(), expected);
}

class ListImagesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = TempDir();
    for (const char* name : {"img1.png", "img2.png", "img10.png", "IMG3.PNG", "photo.jpg", "x.txt",
                             ".hidden.png", "noextension"}) {
      WriteBytes(dir_ + "/" + name, "x");
    }
    fs::create_directory(dir_ + "/sub.png");      // a folder, not an image
    WriteBytes(dir_ + "/sub.png/img0.png", "x");  // not listed: not recursive
    fs::create_symlink(dir_ + "/img1.png", dir_ + "/link5.png");
    fs::create_symlink(dir_ + "/missing.png", dir_ + "/broken.png");
  }
  std::string P(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

TEST_F(ListImagesTest, ExtensionFilterInNaturalOrder) {
  // Case-sensitive natural order: 'I' (0x49) comes before 'i' (0x69).
  // The dangling link broken.png is listed: a frame the user meant, named when read.
  const std::vector<std::string> pngs = {P("IMG3.PNG"), P("broken.png"), P("img1.png"),
                                         P("img2.png"), P("img10.png"),  P("link5.png")};
  EXPECT_EQ(ListImages(dir_, "png"), pngs);
  EXPECT_EQ(ListImages(dir_, ".png"), pngs);
  EXPECT_EQ(ListImages(dir_, "PNG"), pngs);
  EXPECT_EQ(ListImages(dir_, ".PnG"), pngs);
  EXPECT_EQ(ListImages(dir_, "jpg"), std::vector<std::string>{P("photo.jpg")});
  EXPECT_EQ(ListImages(dir_, "txt"), std::vector<std::string>{P("x.txt")});
}

TEST_F(ListImagesTest, EmptyExtensionKeepsEverySupportedImage) {
  const std::vector<std::string> all = {P("IMG3.PNG"), P("broken.png"), P("img1.png"),
                                        P("img2.png"), P("img10.png"),  P("link5.png"),
                                        P("photo.jpg")};
  EXPECT_EQ(ListImages(dir_, ""), all);
}

TEST_F(ListImagesTest, ReadingADanglingLinkNamesIt) {
  ExpectInputError([&] { ReadImageFile(P("broken.png")); },
                   {"image " + Q(P("broken.png")), "is a symbolic link to " + Q(P("missing.png")),
                    "leads nowhere"});
}

TEST_F(ListImagesTest, NoMatchingExtensionNamesFolderAndWhatItHolds) {
  ExpectInputError(
      [&] { ListImages(dir_, "tif"); },
      {"folder " + Q(dir_), "holds no image with extension tif", "supported: png, jpg"});
}

TEST(ListImages, MissingFolder) {
  const std::string missing = TempDir() + "/does_not_exist";
  ExpectInputError([&] { ListImages(missing, "png"); },
                   {"folder " + Q(missing), "does not exist", "expected a folder of images"});
}

TEST(ListImages, FileGivenAsFolder) {
  const std::string file = TempDir() + "/a.png";
  WriteBytes(file, "x");
  ExpectInputError([&] { ListImages(file, "png"); },
                   {"folder " + Q(file), "not a folder", "expected a folder of images"});
}

TEST(ListImages, EmptyFolder) {
  const std::string dir = TempDir();
  ExpectInputError([&] { ListImages(dir, "png"); },
                   {"folder " + Q(dir), "holds no image with extension png", "0 files",
                    "supported: png, jpg, jpeg, tif, tiff, pgm, ppm, pnm, pbm, bmp"});
  ExpectInputError([&] { ListImages(dir, ""); },
                   {"folder " + Q(dir), "holds no image (", "0 files"});
}

TEST(ListImages, FolderWithOnlyNonImageFiles) {
  const std::string dir = TempDir();
  WriteBytes(dir + "/notes.txt", "x");
  WriteBytes(dir + "/poses.csv", "x");
  WriteBytes(dir + "/.hidden.png", "x");
  ExpectInputError([&] { ListImages(dir, ""); },
                   {"folder " + Q(dir), "holds no image", "2 files", "csv, txt"});
}

TEST(ListImages, MessageStaysOnOneLineWhateverTheName) {
  const std::string dir = TempDir() + "/line\nbreak";
  ExpectInputError([&] { ListImages(dir, "png"); }, {"line\\nbreak", "does not exist"});
}

// ---------------------------------------------------------------------------------------------
// ReadImageFile

void ExpectPixel1(const cv::Mat& m, int x, int y, float expected, float tolerance = 1e-6f) {
  ASSERT_EQ(m.type(), CV_32FC1);
  EXPECT_NEAR(m.at<float>(y, x), expected, tolerance) << "at (" << x << ", " << y << ")";
}

void ExpectPixel3(const cv::Mat& m, int x, int y, float b, float g, float r,
                  float tolerance = 1e-6f) {
  ASSERT_EQ(m.type(), CV_32FC3);
  const cv::Vec3f& p = m.at<cv::Vec3f>(y, x);
  EXPECT_NEAR(p[0], b, tolerance) << "blue at (" << x << ", " << y << ")";
  EXPECT_NEAR(p[1], g, tolerance) << "green at (" << x << ", " << y << ")";
  EXPECT_NEAR(p[2], r, tolerance) << "red at (" << x << ", " << y << ")";
}

TEST(ReadImageFile, Grey8BitPng) {
  const std::string path = TempDir() + "/grey8.png";
  std::vector<std::uint8_t> pixels(12);  // 4 x 3
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    pixels[i] = static_cast<std::uint8_t>(i * 20 + 7);
  }
  ASSERT_NO_FATAL_FAILURE(WriteOiio(path, 4, 3, 1, OIIO::TypeDesc::UINT8, pixels));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC1);
  ASSERT_EQ(m.cols, 4);
  ASSERT_EQ(m.rows, 3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 4; ++x)
      ExpectPixel1(m, x, y, static_cast<float>((y * 4 + x) * 20 + 7) / 255.0f);
  }
}

TEST(ReadImageFile, Grey16BitPng) {
  const std::string path = TempDir() + "/grey16.png";
  const std::vector<std::uint16_t> pixels = {0, 32768, 65535, 1234, 40000, 7};
  ASSERT_NO_FATAL_FAILURE(WriteOiio(path, 3, 2, 1, OIIO::TypeDesc::UINT16, pixels));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC1);
  ASSERT_EQ(m.size(), cv::Size(3, 2));
  ExpectPixel1(m, 0, 0, 0.0f);
  ExpectPixel1(m, 1, 0, 32768.0f / 65535.0f);
  ExpectPixel1(m, 2, 0, 1.0f);
  ExpectPixel1(m, 0, 1, 1234.0f / 65535.0f);
  ExpectPixel1(m, 1, 1, 40000.0f / 65535.0f);
  ExpectPixel1(m, 2, 1, 7.0f / 65535.0f);
}

TEST(ReadImageFile, RgbPngComesBackInBgrOrder) {
  const std::string path = TempDir() + "/rgb.png";
  // R, G, B: pure red, then (0, 128, 255).
  const std::vector<std::uint8_t> pixels = {255, 0, 0, 0, 128, 255};
  ASSERT_NO_FATAL_FAILURE(WriteOiio(path, 2, 1, 3, OIIO::TypeDesc::UINT8, pixels));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC3);
  ASSERT_EQ(m.size(), cv::Size(2, 1));
  ExpectPixel3(m, 0, 0, 0.0f, 0.0f, 1.0f);
  ExpectPixel3(m, 1, 0, 1.0f, 128.0f / 255.0f, 0.0f);
}

TEST(ReadImageFile, RgbaPngDropsAlphaWithoutPremultiplying) {
  const std::string path = TempDir() + "/rgba.png";
  // Written by OpenCV (independently of OpenImageIO): B, G, R, A.
  cv::Mat bgra(1, 2, CV_8UC4);
  bgra.at<cv::Vec4b>(0, 0) = cv::Vec4b(0, 100, 200, 64);
  bgra.at<cv::Vec4b>(0, 1) = cv::Vec4b(255, 0, 0, 255);
  ASSERT_TRUE(cv::imwrite(path, bgra));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC3);
  ExpectPixel3(m, 0, 0, 0.0f, 100.0f / 255.0f, 200.0f / 255.0f);
  ExpectPixel3(m, 1, 0, 1.0f, 0.0f, 0.0f);
}

TEST(ReadImageFile, GreyAlphaPngBecomesGrey) {
  const std::string path = TempDir() + "/grey_alpha.png";
  const std::vector<std::uint8_t> pixels = {200, 100, 30, 255};  // (grey, alpha) x 2
  ASSERT_NO_FATAL_FAILURE(WriteOiio(path, 2, 1, 2, OIIO::TypeDesc::UINT8, pixels, 1));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC1);
  ASSERT_EQ(m.size(), cv::Size(2, 1));
  ExpectPixel1(m, 0, 0, 200.0f / 255.0f);
  ExpectPixel1(m, 1, 0, 30.0f / 255.0f);
}

TEST(ReadImageFile, JpegApproximately) {
  const std::string path = TempDir() + "/colour.jpg";
  cv::Mat bgr(16, 16, CV_8UC3, cv::Scalar(50, 100, 200));  // B, G, R
  ASSERT_TRUE(cv::imwrite(path, bgr, {cv::IMWRITE_JPEG_QUALITY, 95}));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC3);
  ASSERT_EQ(m.size(), cv::Size(16, 16));
  const cv::Scalar mean = cv::mean(m);
  EXPECT_NEAR(mean[0], 50.0 / 255.0, 0.02);
  EXPECT_NEAR(mean[1], 100.0 / 255.0, 0.02);
  EXPECT_NEAR(mean[2], 200.0 / 255.0, 0.02);
}

TEST(ReadImageFile, Tiff16BitRgb) {
  const std::string path = TempDir() + "/rgb16.tif";
  const std::vector<std::uint16_t> pixels = {65535, 0, 32768, 1, 2, 3};  // R, G, B x 2
  ASSERT_NO_FATAL_FAILURE(WriteOiio(path, 2, 1, 3, OIIO::TypeDesc::UINT16, pixels));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC3);
  ExpectPixel3(m, 0, 0, 32768.0f / 65535.0f, 0.0f, 1.0f);
  ExpectPixel3(m, 1, 0, 3.0f / 65535.0f, 2.0f / 65535.0f, 1.0f / 65535.0f);
}

TEST(ReadImageFile, PgmAndPpm) {
  const std::string dir = TempDir();
  const std::vector<std::uint8_t> grey = {0, 51, 255, 128};
  ASSERT_NO_FATAL_FAILURE(WriteOiio(dir + "/g.pgm", 2, 2, 1, OIIO::TypeDesc::UINT8, grey));
  const cv::Mat g = ReadImageFile(dir + "/g.pgm");
  ASSERT_EQ(g.type(), CV_32FC1);
  ExpectPixel1(g, 0, 0, 0.0f);
  ExpectPixel1(g, 1, 0, 0.2f);
  ExpectPixel1(g, 0, 1, 1.0f);
  ExpectPixel1(g, 1, 1, 128.0f / 255.0f);

  const std::vector<std::uint8_t> colour = {255, 0, 0, 10, 20, 30};
  ASSERT_NO_FATAL_FAILURE(WriteOiio(dir + "/c.ppm", 2, 1, 3, OIIO::TypeDesc::UINT8, colour));
  const cv::Mat c = ReadImageFile(dir + "/c.ppm");
  ASSERT_EQ(c.type(), CV_32FC3);
  ExpectPixel3(c, 0, 0, 0.0f, 0.0f, 1.0f);
  ExpectPixel3(c, 1, 0, 30.0f / 255.0f, 20.0f / 255.0f, 10.0f / 255.0f);
}

TEST(ReadImageFile, Bmp) {
  const std::string path = TempDir() + "/c.bmp";
  cv::Mat bgr(2, 3, CV_8UC3, cv::Scalar(10, 20, 30));
  bgr.at<cv::Vec3b>(1, 2) = cv::Vec3b(255, 0, 0);
  ASSERT_TRUE(cv::imwrite(path, bgr));
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.size(), cv::Size(3, 2));
  ExpectPixel3(m, 0, 0, 10.0f / 255.0f, 20.0f / 255.0f, 30.0f / 255.0f);
  ExpectPixel3(m, 2, 1, 1.0f, 0.0f, 0.0f);
}

TEST(ReadImageFile, PlainPbmAndPgmWrittenByHand) {
  const std::string dir = TempDir();
  // PBM: 1 is black. PGM with a maximum value of 1023: values scale to [0, 1].
  WriteBytes(dir + "/bits.pbm", "P1\n3 1\n1 0 1\n");
  WriteBytes(dir + "/ten_bits.pgm", "P2\n2 1\n1023\n1023 341\n");
  const cv::Mat bits = ReadImageFile(dir + "/bits.pbm");
  ASSERT_EQ(bits.size(), cv::Size(3, 1));
  ExpectPixel1(bits, 0, 0, 0.0f);
  ExpectPixel1(bits, 1, 0, 1.0f);
  ExpectPixel1(bits, 2, 0, 0.0f);
  const cv::Mat ten_bits = ReadImageFile(dir + "/ten_bits.pgm");
  ASSERT_EQ(ten_bits.size(), cv::Size(2, 1));
  ExpectPixel1(ten_bits, 0, 0, 1.0f);
  ExpectPixel1(ten_bits, 1, 0, 341.0f / 1023.0f, 1e-3f);
}

TEST(ReadImageFile, JpegNamedPngIsReadByContent) {
  const std::string path = TempDir() + "/really_a_jpeg.png";
  ASSERT_TRUE(cv::imwrite(path + ".jpg", cv::Mat(8, 8, CV_8UC1, cv::Scalar(90))));
  fs::rename(path + ".jpg", path);
  const cv::Mat m = ReadImageFile(path);
  ASSERT_EQ(m.type(), CV_32FC1);
  EXPECT_NEAR(cv::mean(m)[0], 90.0 / 255.0, 0.02);
}

TEST(ReadImageFile, MissingFile) {
  const std::string path = TempDir() + "/missing.png";
  ExpectInputError([&] { ReadImageFile(path); },
                   {"image " + Q(path), "does not exist", "expected a PNG/JPEG"});
}

TEST(ReadImageFile, FolderIsNotAnImage) {
  const std::string dir = TempDir();
  ExpectInputError([&] { ReadImageFile(dir); }, {"image " + Q(dir), "not a regular file"});
}

TEST(ReadImageFile, GarbagePng) {
  const std::string path = TempDir() + "/garbage.png";
  std::string text;
  for (int i = 0; i < 100; ++i) text += "this is not an image\n";
  WriteBytes(path, text);
  ExpectInputError([&] { ReadImageFile(path); },
                   {"image " + Q(path) + " cannot be decoded: ", "expected a PNG/JPEG"});
}

TEST(ReadImageFile, EmptyFile) {
  const std::string path = TempDir() + "/empty.png";
  WriteBytes(path, "");
  ExpectInputError([&] { ReadImageFile(path); }, {"image " + Q(path) + " is an empty file"});
}

TEST(ReadImageFile, TruncatedPng) {
  const std::string path = TempDir() + "/truncated.png";
  ASSERT_TRUE(cv::imwrite(path, Noise(64, 64, CV_8UC3, 1)));
  ASSERT_NO_THROW(ReadImageFile(path));
  TruncateToHalf(path);
  ExpectInputError([&] { ReadImageFile(path); }, {"image " + Q(path) + " cannot be decoded: "});
}

TEST(ReadImageFile, TruncatedJpeg) {
  const std::string path = TempDir() + "/truncated.jpg";
  ASSERT_TRUE(cv::imwrite(path, Noise(64, 64, CV_8UC3, 2)));
  ASSERT_NO_THROW(ReadImageFile(path));
  TruncateToHalf(path);
  ExpectInputError([&] { ReadImageFile(path); }, {"image " + Q(path) + " cannot be decoded: "});
}

TEST(ReadImageFile, TruncatedTiff) {
  const std::string path = TempDir() + "/truncated.tif";
  ASSERT_TRUE(cv::imwrite(path, Noise(64, 64, CV_8UC3, 3)));
  ASSERT_NO_THROW(ReadImageFile(path));
  TruncateToHalf(path);
  ExpectInputError([&] { ReadImageFile(path); }, {"image " + Q(path) + " cannot be decoded: "});
}

TEST(ReadImageFile, ErrorsPrintNothing) {
  const std::string dir = TempDir();
  ASSERT_TRUE(cv::imwrite(dir + "/t.png", Noise(64, 64, CV_8UC1, 4)));
  ASSERT_TRUE(cv::imwrite(dir + "/t.jpg", Noise(64, 64, CV_8UC1, 5)));
  ASSERT_TRUE(cv::imwrite(dir + "/t.tif", Noise(64, 64, CV_8UC1, 6)));
  TruncateToHalf(dir + "/t.png");
  TruncateToHalf(dir + "/t.jpg");
  TruncateToHalf(dir + "/t.tif");
  WriteBytes(dir + "/g.png", std::string(1000, 'g'));
  WriteBytes(dir + "/g.jpg", std::string(1000, 'g'));
  ::testing::internal::CaptureStderr();
  for (const char* name : {"t.png", "t.jpg", "t.tif", "g.png", "g.jpg"}) {
    EXPECT_THROW(ReadImageFile(dir + "/" + name), InputError) << name;
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

// The common formats are decoded by OpenCV's codecs, the rest by the OpenImageIO module: both
// must give the same frame for the files either can read.
TEST(ReadImageFile, OpenCVAndOpenImageIOPathsAgree) {
  const std::string dir = TempDir();
  const auto oiio_read =
      reinterpret_cast<OpenableOiioRead>(ModuleSymbol("oiio", "openable_oiio_read"));
  cv::Mat grey16(20, 30, CV_16UC1);
  cv::randu(grey16, 0, 65536);
  cv::Mat rgba = Noise(30, 20, CV_8UC4, 21);
  std::vector<std::pair<std::string, cv::Mat>> files = {
      {"grey.png", Noise(30, 20, CV_8UC1, 11)},   {"grey16.png", grey16},
      {"colour.png", Noise(30, 20, CV_8UC3, 12)}, {"rgba.png", rgba},
      {"grey.pgm", Noise(30, 20, CV_8UC1, 13)},   {"grey16.pgm", grey16},
      {"colour.ppm", Noise(30, 20, CV_8UC3, 14)}, {"colour.bmp", Noise(30, 20, CV_8UC3, 15)},
      {"colour.jpg", Noise(30, 20, CV_8UC3, 16)}};
  for (const auto& [name, image] : files) {
    const std::string path = dir + "/" + name;
    ASSERT_TRUE(cv::imwrite(path, image)) << name;
    const cv::Mat fast = ReadImageFile(path);
    cv::Mat reference;
    oiio_read(path, reference);
    ASSERT_EQ(fast.type(), reference.type()) << name;
    ASSERT_EQ(fast.size(), reference.size()) << name;
    // JPEG: both decode with libjpeg, possibly with different IDCT or upsampling settings.
    // 16-bit PNM: OpenImageIO reads it through float and loses one step at the top
    // (65535 -> 65534); OpenCV is exact, as checked against the written values below.
    const double tolerance = name == "colour.jpg"   ? 3.0 / 255.0
                             : name == "grey16.pgm" ? 1.0 / 65535 + 1e-7
                                                    : 1e-6;
    EXPECT_LE(cv::norm(fast, reference, cv::NORM_INF), tolerance) << name;
    if (name == "colour.jpg") continue;
    cv::Mat expected = image;
    if (image.channels() == 4) cv::cvtColor(image, expected, cv::COLOR_BGRA2BGR);
    expected.convertTo(expected, CV_MAKETYPE(CV_32F, expected.channels()),
                       image.depth() == CV_8U ? 1.0 / 255 : 1.0 / 65535);
    EXPECT_LE(cv::norm(fast, expected, cv::NORM_INF), 1e-6) << name;
  }
}

// A PNG whose chunk CRC does not match is left to OpenImageIO, which names the problem without
// printing libpng's messages.
TEST(ReadImageFile, PngWithBadCrcIsRefusedQuietly) {
  const std::string dir = TempDir();
  const std::string path = dir + "/crc.png";
  ASSERT_TRUE(cv::imwrite(path, Noise(64, 64, CV_8UC1, 8)));
  std::string bytes = ReadBytes(path);
  const std::size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 10] = static_cast<char>(bytes[idat + 10] ^ 0x5a);
  WriteBytes(path, bytes);
  ::testing::internal::CaptureStderr();
  ExpectInputError([&] { ReadImageFile(path); },
                   {"image " + Q(path) +
                    " cannot be decoded: damaged PNG: the checksum (CRC) "
                    "of its IDAT chunk does not match its data"});
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

TEST(DecodeImageBytes, DecodesLikeReadImageFileThroughBothLibraries) {
  const std::string png = TempDir() + "/bytes.png";
  ASSERT_TRUE(cv::imwrite(png, Noise(7, 5, CV_8UC3, 3)));
  const std::string tif = TempDir() + "/bytes.tif";
  const std::vector<std::uint16_t> pixels = {65535, 0, 32768, 1, 2, 3};
  ASSERT_NO_FATAL_FAILURE(WriteOiio(tif, 2, 1, 3, OIIO::TypeDesc::UINT16, pixels));
  for (const std::string& path : {png, tif}) {  // OpenCV's codecs, OpenImageIO from memory
    const cv::Mat from_file = ReadImageFile(path);
    const cv::Mat from_bytes = DecodeImageBytes(ReadBytes(path), "memory");
    ASSERT_EQ(from_bytes.type(), from_file.type()) << path;
    ASSERT_EQ(from_bytes.size(), from_file.size()) << path;
    EXPECT_EQ(cv::norm(from_bytes, from_file, cv::NORM_INF), 0.0) << path;
  }
  ExpectInputError([] { DecodeImageBytes("", "empty"); }, {"empty", "0 bytes"});
  ExpectInputError([] { DecodeImageBytes(std::string(100, 'x'), "junk.bin"); },
                   {"junk.bin", "cannot be decoded"});
}

// A PNG whose chunks are sound but hold no IHDR (signature + IEND, 20 bytes): the colour type
// was read at byte 25, past the end (heap-buffer-overflow under AddressSanitizer).
TEST(ReadImageFile, PngWithoutHeaderChunk) {
  const std::string iend("\x89PNG\r\n\x1a\n\0\0\0\0IEND\xae\x42\x60\x82", 20);
  const std::string path = TempDir() + "/iend_only.png";
  WriteBytes(path, iend);
  ExpectInputError([&] { ReadImageFile(path); }, {Q(path), "cannot be decoded"});
  ExpectInputError([&] { DecodeImageBytes(iend, "iend_only.png"); },
                   {"iend_only.png", "cannot be decoded"});
}

// Found by tests/fuzz/image_fuzzer.cc: a PGM header announcing 10^12 pixels made the
// OpenImageIO module allocate them (an abort under AddressSanitizer) before reading anything.
TEST(ReadImageFile, HugeAnnouncedSizeIsRefusedBeforeAllocating) {
  const std::string bytes = "P5\n1000000 1000000\n255\nabc";
  const std::string path = TempDir() + "/huge.pgm";
  WriteBytes(path, bytes);
  ExpectInputError([&] { ReadImageFile(path); }, {Q(path), "too large", "1000000 x 1000000"});
  ExpectInputError([&] { DecodeImageBytes(bytes, "huge.pgm"); }, {"huge.pgm", "too large"});
}

// Found by tests/fuzz/image_fuzzer.cc: a damaged PAM header ("P7", a format neither OpenCV nor
// the signature table names) went to every reader of OpenImageIO, its FFmpeg (video) reader
// included, which threw std::length_error (ending the process) in a long fuzzing run. Such a
// file is now offered to still-image readers only, and the message names the file the user
// gave, never the temporary copy that OpenImageIO reads bytes from.
TEST(ReadImageFile, UnrecognisedContentsAreNamedWithoutTheTemporaryCopy) {
  const std::string bytes(
      "\x50\x37\x0a\x38\x20\x36\x0a\x32\x35\x35\x0a\x32\x48\xa4\x35\x0a\x32\x48\xa4\x3f\x3a\xc5"
      "\x4d\xbe\xb0\x19\xd5\x70\xa1\x1e\x68\x92\x60\x80\x9e\xa9\xce\x51\x26\x87\xe2\x8f\x18\x4a"
      "\x80\x27\x41\xf1\xc9\xc5\xd9\xc3\x63\x2e\x4b\xc2\xc0\x9b\xdf\x38\x17\xef\x2c\x69\xeb\x87"
      "\x4f\x15\x1b\xd1\x50\x04\xe6\x50\x5b\x69\xbc\x3f\x3a\xc5\x4d\xbe\xb0\x19\xd5\x70\xa1\x1e"
      "\x68\x92\x60\x80\x9e\xa9\xce\x51\x26\x87\xe2\x8f\x18\x4a\x80\x27\x41\xf1\xc9\xc5\xd9\xc3"
      "\x63\x2e\x4b\xc2\xc0\x9b\xdf\x38\x17\xef\x2c\x69\xeb\x87\x4f\x15\x1b\xd1\x50\x04\xe6\x50"
      "\x5b\x69\xbc\x28\x17\xe9\x80\xec\xba\x76\x6f\x43\xbc\x83",
      146);
  ASSERT_EQ(bytes.compare(0, 3, "P7\n"), 0);
  ExpectInputError([&] { DecodeImageBytes(bytes, "damaged.pam"); },
                   {"damaged.pam", "cannot be decoded", "no image reader"});
  try {
    DecodeImageBytes(bytes, "damaged.pam");
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find("openable_image_"), std::string::npos) << e.what();
  }
  const std::string path = TempDir() + "/damaged";
  WriteBytes(path, bytes);
  ExpectInputError([&] { ReadImageFile(path); }, {Q(path), "cannot be decoded"});
}

TEST(ModuleSymbol, MissingModuleIsNamed) {
  ExpectInputError([] { ModuleSymbol("no_such_module", "f"); },
                   {"libopenable_no_such_module.so", "cannot be loaded", "OPENABLE_MODULE_PATH"});
  ExpectInputError([] { ModuleSymbol("oiio", "no_such_symbol"); },
                   {"libopenable_oiio.so", "no_such_symbol"});
}

// Damaged files (bytes flipped in their second half, or cut at any length) either read as an
// image of the frame format or throw InputError: never a crash or another exception.
TEST(ReadImageFile, DamagedFilesNeverCrash) {
  const std::string dir = TempDir();
  const cv::Mat noise = Noise(32, 24, CV_8UC3, 7);
  std::mt19937 rng(99);
  int errors = 0;
  int decoded = 0;
  ::testing::internal::CaptureStderr();  // libpng reports CRC errors on stderr
  for (const char* ext : {"png", "jpg", "tif", "ppm", "bmp"}) {
    const std::string original = dir + "/original." + ext;
    ASSERT_TRUE(cv::imwrite(original, noise)) << ext;
    const std::string bytes = ReadBytes(original);
    for (int variant = 0; variant < 30; ++variant) {
      std::string damaged = bytes;
      if (variant % 2 == 0) {
        std::uniform_int_distribution<std::size_t> at(damaged.size() / 2, damaged.size() - 1);
        for (int k = 0; k < 1 + variant / 4; ++k) {
          char& byte = damaged[at(rng)];
          byte = static_cast<char>(static_cast<unsigned char>(byte) ^ (1 + rng() % 255));
        }
      } else {
        damaged.resize(std::uniform_int_distribution<std::size_t>(1, bytes.size() - 1)(rng));
      }
      const std::string path = dir + "/damaged_" + std::to_string(variant) + "." + ext;
      WriteBytes(path, damaged);
      try {
        const cv::Mat m = ReadImageFile(path);
        ++decoded;
        EXPECT_TRUE(m.type() == CV_32FC1 || m.type() == CV_32FC3) << path;
        double low = 0;
        double high = 0;
        cv::minMaxLoc(m.reshape(1), &low, &high);
        EXPECT_GE(low, 0.0) << path;
        EXPECT_LE(high, 1.0) << path;
      } catch (const InputError& e) {
        ++errors;
        EXPECT_NE(std::string(e.what()).find(Q(path)), std::string::npos) << e.what();
      }
    }
  }
  ::testing::internal::GetCapturedStderr();
  EXPECT_GT(errors, 0);
  EXPECT_GT(decoded, 0);  // bytes flipped inside JPEG/BMP pixel data still decode
}

// ---------------------------------------------------------------------------------------------
// OpenImageFolder

class ImageFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = TempDir();
    // Natural order: f1, f2, f10, f11, f20; each holds one grey level.
    for (int value : {1, 2, 10, 11, 20}) {
      const std::vector<std::uint8_t> pixels(4, static_cast<std::uint8_t>(value * 10));
      ASSERT_NO_FATAL_FAILURE(WriteOiio(P(value), 2, 2, 1, OIIO::TypeDesc::UINT8, pixels));
    }
    WriteBytes(dir_ + "/readme.txt", "x");
  }
  std::string P(int value) const { return dir_ + "/f" + std::to_string(value) + ".png"; }
  static float Grey(const cv::Mat& m) {
    EXPECT_EQ(m.type(), CV_32FC1);
    return m.at<float>(0, 0);
  }
  std::string dir_;
};

TEST_F(ImageFolderTest, WholeFolder) {
  const auto source = OpenImageFolder(dir_, "png", 0, -1);
  ASSERT_EQ(source->Size(), 5);
  EXPECT_TRUE(source->ParallelReads());
  const int values[] = {1, 2, 10, 11, 20};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(source->FrameName(i), P(values[i]));
    EXPECT_NEAR(Grey(source->Read(i)), values[i] * 10 / 255.0f, 1e-6f);
  }
}

TEST_F(ImageFolderTest, RangeSelection) {
  const auto source = OpenImageFolder(dir_, ".png", 1, 4);
  ASSERT_EQ(source->Size(), 3);
  EXPECT_EQ(source->FrameName(0), P(2));
  EXPECT_EQ(source->FrameName(2), P(11));
  EXPECT_NEAR(Grey(source->Read(2)), 110 / 255.0f, 1e-6f);
  EXPECT_NEAR(Grey(source->Read(0)), 20 / 255.0f, 1e-6f);

  const auto tail = OpenImageFolder(dir_, "", 3, -1);
  ASSERT_EQ(tail->Size(), 2);
  EXPECT_EQ(tail->FrameName(0), P(11));
  EXPECT_EQ(tail->FrameName(1), P(20));

  const auto last_one = OpenImageFolder(dir_, "png", 4, 5);
  ASSERT_EQ(last_one->Size(), 1);
  EXPECT_EQ(last_one->FrameName(0), P(20));
}

TEST_F(ImageFolderTest, RangeErrors) {
  for (const auto& range : std::vector<std::pair<int, int>>{
           {3, 2}, {2, 2}, {0, 6}, {-1, 3}, {-1, -1}, {5, -1}, {0, -2}}) {
    const int first = range.first;
    const int last = range.second;
    SCOPED_TRACE(std::to_string(first) + ", " + std::to_string(last));
    ExpectInputError([&] { OpenImageFolder(dir_, "png", first, last); },
                     {"Initial_image/Final_image: range [" + std::to_string(first) + ", ",
                      "is empty or outside the 5 images of folder " + Q(dir_)});
  }
}

TEST_F(ImageFolderTest, IndexOutsideTheSourceIsABug) {
  const auto source = OpenImageFolder(dir_, "png", 1, 3);
  EXPECT_THROW(source->Read(2), std::logic_error);
  EXPECT_THROW(source->Read(-1), std::logic_error);
  EXPECT_THROW(source->FrameName(2), std::logic_error);
  // Not an input error: the caller broke a precondition.
  try {
    source->Read(5);
  } catch (const InputError&) {
    ADD_FAILURE() << "InputError for an index out of range";
  } catch (const std::logic_error&) {
  }
}

TEST_F(ImageFolderTest, ParallelReadsGiveTheRightFrames) {
  const auto source = OpenImageFolder(dir_, "png", 0, -1);
  const int values[] = {1, 2, 10, 11, 20};
  std::vector<int> wrong(4, 0);
  std::vector<std::thread> threads;
  threads.reserve(4);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int round = 0; round < 10; ++round) {
        for (int i = 0; i < source->Size(); ++i) {
          const int k = (i + t) % source->Size();
          const cv::Mat m = source->Read(k);
          if (m.type() != CV_32FC1 ||
              std::abs(m.at<float>(0, 0) - static_cast<float>(values[k] * 10) / 255.0f) > 1e-6f) {
            ++wrong[t];
          }
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(wrong[t], 0) << "thread " << t;
}

TEST_F(ImageFolderTest, CorruptFrameIsNamedWhenRead) {
  WriteBytes(dir_ + "/f3.png", "not a png");
  const auto source = OpenImageFolder(dir_, "png", 0, -1);
  ASSERT_EQ(source->Size(), 6);
  ASSERT_EQ(source->FrameName(2), dir_ + "/f3.png");
  ExpectInputError([&] { source->Read(2); }, {"image " + Q(dir_ + "/f3.png"), "cannot be decoded"});
}

TEST(OpenImageFolder, MissingFolder) {
  const std::string missing = TempDir() + "/nothing";
  ExpectInputError([&] { OpenImageFolder(missing, "png", 0, -1); },
                   {"folder " + Q(missing), "does not exist"});
}

// ---------------------------------------------------------------------------------------------
// OpenVideo

constexpr int kVideoFrames = 12;

double Brightness(int frame) { return 20.0 + 18.0 * frame; }  // 20 .. 218 of 255

// Writes a small MJPG video whose frame k is a uniform grey of Brightness(k) with a small
// pattern; returns false when this OpenCV cannot write such a video.
bool WriteTestVideo(const std::string& path) {
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, cv::Size(64, 48),
                         true);
  if (!writer.isOpened()) return false;
  for (int k = 0; k < kVideoFrames; ++k) {
    writer.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(Brightness(k))));
  }
  writer.release();
  return true;
}

double MeanOf(const cv::Mat& frame) {
  const cv::Scalar s = cv::mean(frame);
  double sum = 0;
  for (int c = 0; c < frame.channels(); ++c) sum += s[c];
  return sum / frame.channels();
}

class VideoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = TempDir() + "/video.avi";
    if (!WriteTestVideo(path_)) GTEST_SKIP() << "this OpenCV cannot write an MJPG .avi video";
  }
  // Expects `frame` to be frame `index` of the video.
  static void ExpectFrame(const cv::Mat& frame, int index) {
    ASSERT_EQ(frame.type(), CV_32FC3);
    ASSERT_EQ(frame.size(), cv::Size(64, 48));
    EXPECT_NEAR(MeanOf(frame), Brightness(index) / 255.0, 3.0 / 255.0) << "frame " << index;
  }
  std::string path_;
};

TEST_F(VideoTest, CountsAndReadsFramesInOrder) {
  const auto source = OpenVideo(path_, 0, -1);
  ASSERT_EQ(source->Size(), kVideoFrames);
  EXPECT_FALSE(source->ParallelReads());
  EXPECT_EQ(source->FrameName(0), path_ + "#0");
  EXPECT_EQ(source->FrameName(11), path_ + "#11");
  for (int i = 0; i < kVideoFrames; ++i) ExpectFrame(source->Read(i), i);
}

TEST_F(VideoTest, StepBackAndSkipsGiveTheRightFrames) {
  const auto source = OpenVideo(path_, 0, -1);
  for (int i : {7, 2, 9, 9, 0, 11, 3, 4, 1}) ExpectFrame(source->Read(i), i);
}

TEST_F(VideoTest, RangeSelection) {
  const auto source = OpenVideo(path_, 4, 10);
  ASSERT_EQ(source->Size(), 6);
  EXPECT_EQ(source->FrameName(0), path_ + "#4");
  EXPECT_EQ(source->FrameName(5), path_ + "#9");
  ExpectFrame(source->Read(0), 4);
  ExpectFrame(source->Read(5), 9);
  ExpectFrame(source->Read(1), 5);
  EXPECT_THROW(source->Read(6), std::logic_error);

  const auto tail = OpenVideo(path_, 10, -1);
  ASSERT_EQ(tail->Size(), 2);
  ExpectFrame(tail->Read(1), 11);
}

TEST_F(VideoTest, RangeErrors) {
  for (const auto& range :
       std::vector<std::pair<int, int>>{{10, 13}, {5, 5}, {-1, 3}, {12, -1}, {6, 2}}) {
    const int first = range.first;
    const int last = range.second;
    SCOPED_TRACE(std::to_string(first) + ", " + std::to_string(last));
    ExpectInputError([&] { OpenVideo(path_, first, last); },
                     {"Initial_image/Final_image: range [" + std::to_string(first) + ", ",
                      "is empty or outside the 12 frames of video " + Q(path_)});
  }
}

TEST(OpenVideo, MissingVideo) {
  const std::string path = TempDir() + "/missing.avi";
  ExpectInputError([&] { OpenVideo(path, 0, -1); },
                   {"video " + Q(path), "expected a video file readable by FFmpeg/GStreamer"});
}

TEST(OpenVideo, TextFileIsNotAVideo) {
  const std::string path = TempDir() + "/notes.avi";
  std::string text;
  for (int i = 0; i < 50; ++i) text += "this is a text file, not a video\n";
  WriteBytes(path, text);
  ExpectInputError([&] { OpenVideo(path, 0, -1); },
                   {"video " + Q(path), "expected a video file readable by FFmpeg/GStreamer"});
  // Named .txt, FFmpeg's tty demuxer would render it as frames: refused by its extension.
  const std::string txt = TempDir() + "/Config.txt";
  WriteBytes(txt, text);
  ExpectInputError([&] { OpenVideo(txt, 0, -1); },
                   {"video " + Q(txt), "is a text file (.txt)", "expected a video file"});
}

}  // namespace
}  // namespace openable
