#include "OpenABLE/evaluation/matrix_file.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace openable::testing;  // NOLINT: TempDir, WriteBytes, Q, ExpectInputError

// A .npy file from its parts: magic, version, little-endian header length (2 bytes for 1.0,
// 4 for 2.0 and 3.0), the dict padded to a multiple of 64 bytes with '\n' last, then `data`
// exactly as given.
std::string Npy(int major, const std::string& dict, const std::string& data) {
  const std::size_t preamble = major == 1 ? 10 : 12;
  std::string header = dict;
  while ((preamble + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out = "\x93NUMPY";
  out += static_cast<char>(major);
  out += '\0';
  const std::size_t n = header.size();
  out += static_cast<char>(n & 0xff);
  out += static_cast<char>((n >> 8) & 0xff);
  if (major != 1) out += std::string(2, '\0');
  return out + header + data;
}

// Bytes from a list of values 0..255.
std::string B(std::initializer_list<int> bytes) {
  std::string s;
  for (int b : bytes) s += static_cast<char>(b);
  return s;
}

void ExpectMatrix(const cv::Mat1f& m, const std::vector<std::vector<float>>& expected) {
  ASSERT_EQ(m.rows, static_cast<int>(expected.size()));
  for (int r = 0; r < m.rows; ++r) {
    ASSERT_EQ(m.cols, static_cast<int>(expected[static_cast<std::size_t>(r)].size()));
    for (int c = 0; c < m.cols; ++c) {
      EXPECT_EQ(m(r, c), expected[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)])
          << "at (" << r << ", " << c << ")";
    }
  }
}

// ---------------------------------------------------------------------------------------------
// .npy

TEST(MatrixFileNpy, Float32COrderVersion1) {
  const std::string path = TempDir() + "/m.npy";
  // [[1, 2.5, -1], [0.5, 0, 3]] as little-endian float32.
  WriteBytes(path,
             Npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }",
                 B({0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0x20, 0x40, 0x00, 0x00, 0x80, 0xbf,
                    0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40, 0x40})));
  ExpectMatrix(ReadMatrixFile(path), {{1.f, 2.5f, -1.f}, {0.5f, 0.f, 3.f}});
}

TEST(MatrixFileNpy, Int16FortranOrder) {
  const std::string path = TempDir() + "/m.npy";
  // [[1, 2, -2], [4, 5, 6]] stored column by column: 1, 4, 2, 5, -2, 6.
  WriteBytes(path,
             Npy(1, "{'descr': '<i2', 'fortran_order': True, 'shape': (2, 3), }",
                 B({0x01, 0x00, 0x04, 0x00, 0x02, 0x00, 0x05, 0x00, 0xfe, 0xff, 0x06, 0x00})));
  ExpectMatrix(ReadMatrixFile(path), {{1, 2, -2}, {4, 5, 6}});
}

TEST(MatrixFileNpy, Uint8Version2AndBoolVersion3) {
  const std::string u8 = TempDir() + "/u8.npy";
  WriteBytes(u8, Npy(2, "{'descr': '|u1', 'fortran_order': False, 'shape': (3, 2), }",
                     B({0, 255, 7, 1, 128, 0})));
  ExpectMatrix(ReadMatrixFile(u8), {{0, 255}, {7, 1}, {128, 0}});

  const std::string b1 = TempDir() + "/bool.npy";
  WriteBytes(
      b1, Npy(3, "{'descr': '|b1', 'fortran_order': False, 'shape': (2, 2), }", B({1, 0, 0, 1})));
  ExpectMatrix(ReadMatrixFile(b1), {{1, 0}, {0, 1}});
}

TEST(MatrixFileNpy, WideIntegerAndDoubleTypes) {
  const std::string dir = TempDir();
  struct Case {
    const char* descr;
    std::string data;
    float expected;
  };
  const Case cases[] = {
      {"|i1", B({0xff}), -1.f},
      {"<u2", B({0xff, 0xff}), 65535.f},
      {"<i4", B({0x60, 0x79, 0xfe, 0xff}), -100000.f},
      {"<u4", B({0x00, 0x28, 0x6b, 0xee}), 4000000000.f},
      {"<i8", B({0xfd, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff}), -3.f},
      {"<u8", B({0x2a, 0, 0, 0, 0, 0, 0, 0}), 42.f},
      {"<f8", B({0, 0, 0, 0, 0, 0, 0xf8, 0x3f}), 1.5f},
  };
  for (const Case& c : cases) {
    const std::string path = dir + "/" + std::string(c.descr + 1) + ".npy";
    // Shape written with a space and a Python 2 'L' suffix, keys in another order.
    WriteBytes(path, Npy(1,
                         std::string("{'shape': (1L, 1), 'fortran_order': False, 'descr': '") +
                             c.descr + "'}",
                         c.data));
    const cv::Mat1f m = ReadMatrixFile(path);
    ASSERT_EQ(m.rows, 1) << c.descr;
    ASSERT_EQ(m.cols, 1) << c.descr;
    EXPECT_EQ(m(0, 0), c.expected) << c.descr;
  }
}

TEST(MatrixFileNpy, ErrorsNameTheFileAndTheProblem) {
  const std::string dir = TempDir();
  const std::string one_d = dir + "/one_d.npy";
  WriteBytes(one_d, Npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (2,), }",
                        std::string(8, '\0')));
  ExpectInputError([&] { ReadMatrixFile(one_d); }, {Q(one_d), "shape (2,)", "expected 2"});

  const std::string big = dir + "/big.npy";
  WriteBytes(big, Npy(1, "{'descr': '>f4', 'fortran_order': False, 'shape': (1, 1), }",
                      std::string(4, '\0')));
  ExpectInputError([&] { ReadMatrixFile(big); }, {Q(big), "\">f4\"", "little-endian"});

  const std::string complex = dir + "/complex.npy";
  WriteBytes(complex, Npy(1, "{'descr': '<c8', 'fortran_order': False, 'shape': (1, 1), }",
                          std::string(8, '\0')));
  ExpectInputError([&] { ReadMatrixFile(complex); }, {Q(complex), "\"<c8\"", "f8"});

  const std::string structured = dir + "/structured.npy";
  WriteBytes(structured,
             Npy(1, "{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (1, 1), }",
                 std::string(4, '\0')));
  ExpectInputError([&] { ReadMatrixFile(structured); }, {Q(structured), "structured"});

  const std::string truncated = dir + "/truncated.npy";
  WriteBytes(truncated, Npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), }",
                            std::string(12, '\0')));
  ExpectInputError([&] { ReadMatrixFile(truncated); },
                   {Q(truncated), "truncated", "12 bytes", "expected 16"});

  const std::string version = dir + "/version.npy";
  WriteBytes(version, Npy(4, "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 1), }",
                          std::string(4, '\0')));
  ExpectInputError([&] { ReadMatrixFile(version); }, {Q(version), "4.0", "1.0, 2.0 or 3.0"});

  const std::string magic = dir + "/magic.npy";
  WriteBytes(magic, "1 2 3\n4 5 6\n");
  ExpectInputError([&] { ReadMatrixFile(magic); }, {Q(magic), "magic"});

  const std::string no_shape = dir + "/no_shape.npy";
  WriteBytes(no_shape, Npy(1, "{'descr': '<f4', 'fortran_order': False}", std::string(4, '\0')));
  ExpectInputError([&] { ReadMatrixFile(no_shape); }, {Q(no_shape), "'shape'"});
}

// ---------------------------------------------------------------------------------------------
// Text

TEST(MatrixFileText, CommentsCommasBlankLinesAndCrLf) {
  const std::string path = TempDir() + "/m.csv";
  WriteBytes(path,
             "# a 3x3 matrix\n"
             "1, 2, 3\n"
             "\n"
             "4 5\t6   # trailing comment\r\n"
             "   # only a comment\n"
             "7,8,-9.5e1,\n"
             "+1e-1 0 1");
  ExpectMatrix(ReadMatrixFile(path), {{1, 2, 3}, {4, 5, 6}, {7, 8, -95}, {0.1f, 0, 1}});
}

TEST(MatrixFileText, RaggedRowsNameTheLineAndTheFirstRow) {
  const std::string path = TempDir() + "/gt.txt";
  WriteBytes(path, "# header\n1 2 3\n4 5 6 7 8\n");
  ExpectInputError([&] { ReadMatrixFile(path); },
                   {Q(path) + ":3:", "row has 5 values", "expected 3", "first row (line 2)"});
}

TEST(MatrixFileText, BadValuesAndEmptyFiles) {
  const std::string dir = TempDir();
  const std::string word = dir + "/word.dat";
  WriteBytes(word, "1 2\n3 x4\n");
  ExpectInputError([&] { ReadMatrixFile(word); },
                   {Q(word) + ":2:", "\"x4\"", "column 2", "not a number"});

  const std::string empty_field = dir + "/empty_field.csv";
  WriteBytes(empty_field, "1,,2\n");
  ExpectInputError([&] { ReadMatrixFile(empty_field); },
                   {Q(empty_field) + ":1:", "empty value in column 2"});

  const std::string comments = dir + "/comments.txt";
  WriteBytes(comments, "# nothing\n\n");
  ExpectInputError([&] { ReadMatrixFile(comments); }, {Q(comments), "no rows"});
}

// ---------------------------------------------------------------------------------------------
// Images and file errors

TEST(MatrixFileImage, GreyColourAndSixteenBit) {
  const std::string dir = TempDir();
  cv::Mat1b grey(2, 3);
  grey << 0, 255, 10, 20, 30, 40;
  ASSERT_TRUE(cv::imwrite(dir + "/grey.png", grey));
  ExpectMatrix(ReadMatrixFile(dir + "/grey.png"), {{0, 255, 10}, {20, 30, 40}});

  // Grey pixels stored as colour stay the same grey level.
  cv::Mat3b colour(1, 2);
  colour(0, 0) = cv::Vec3b(200, 200, 200);
  colour(0, 1) = cv::Vec3b(0, 0, 0);
  ASSERT_TRUE(cv::imwrite(dir + "/colour.bmp", colour));
  ExpectMatrix(ReadMatrixFile(dir + "/colour.bmp"), {{200, 0}});

  cv::Mat1w wide(1, 2);
  wide << 40000, 3;
  ASSERT_TRUE(cv::imwrite(dir + "/wide.png", wide));
  ExpectMatrix(ReadMatrixFile(dir + "/wide.png"), {{40000, 3}});
}

TEST(MatrixFileErrors, MissingFileExtensionAndUndecodableImage) {
  const std::string dir = TempDir();
  ExpectInputError([&] { ReadMatrixFile(dir + "/absent.npy"); },
                   {Q(dir + "/absent.npy"), "does not exist"});
  ExpectInputError([&] { ReadMatrixFile(dir); }, {Q(dir), "folder"});

  WriteBytes(dir + "/m.json", "[[1]]");
  ExpectInputError([&] { ReadMatrixFile(dir + "/m.json"); },
                   {Q(dir + "/m.json"), ".json", "expected .npy"});

  WriteBytes(dir + "/bad.png", "this is not a PNG");
  ExpectInputError([&] { ReadMatrixFile(dir + "/bad.png"); },
                   {Q(dir + "/bad.png"), "cannot be decoded"});
}

}  // namespace
}  // namespace openable
