// The .npy module: headers padded as the format asks, and what is written read back.
#include "OpenABLE/io/npy.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

// Header layout by hand (NumPy's format description): 6 magic bytes, version 1.0, a
// little-endian uint16 length, the dict, spaces, '\n'; the data starts at a multiple of 64.
TEST(Npy, HeaderIsTheDictPaddedToSixtyFourBytes) {
  const std::string h = NpyHeaderOf("'<f4'", "(3, 4)");
  ASSERT_EQ(h.size() % 64, 0u);
  EXPECT_EQ(h.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const std::size_t length = static_cast<unsigned char>(h[8]) | static_cast<unsigned char>(h[9])
                                                                    << 8;
  EXPECT_EQ(length + 10, h.size());
  const std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }";
  EXPECT_EQ(h.substr(10, dict.size()), dict);
  EXPECT_EQ(h.back(), '\n');
  EXPECT_EQ(h.find_first_not_of(' ', 10 + dict.size()), h.size() - 1);
  EXPECT_EQ(NpyHeader(3, 4), h);
}

TEST(Npy, EncodedMatrixDecodesToTheSameValues) {
  cv::Mat1f m(3, 5);
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c) m(r, c) = 0.25f * r - 1.5f * c + 1e-7f * r * c;
  const std::string bytes = EncodeNpy(m);
  const std::string header = NpyHeader(3, 5);
  ASSERT_EQ(bytes.size(), header.size() + 15 * sizeof(float));
  float first = 0;
  std::memcpy(&first, bytes.data() + header.size() + 4 * (1 * 5 + 2), sizeof first);
  EXPECT_EQ(first, m(1, 2));  // C order, little-endian float32
  const cv::Mat1f back = DecodeNpyMatrix(bytes, "m.npy");
  ASSERT_EQ(back.size(), m.size());
  EXPECT_EQ(cv::countNonZero(back != m), 0);
}

TEST(Npy, BadBytesAreOneLineNamingTheSource) {
  for (const std::string& bytes :
       {std::string("not a numpy file"), NpyHeader(2, 2) + std::string(3, '\0'),
        NpyHeaderOf("'<c8'", "(1, 1)") + std::string(8, '\0')}) {
    try {
      DecodeNpyMatrix(bytes, "x.npy");
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("x.npy: ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace openable
