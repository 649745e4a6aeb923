// image_codec.h: the formats recognised from their bytes, and PNG decoding (libpng) and writing
// (libdeflate) against OpenCV's own codecs.
#include "OpenABLE/io/image_codec.h"

#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"

namespace openable {
namespace {

cv::Mat Random(int rows, int cols, int type, int seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

// What the frame reader took from OpenCV's decoder: IMREAD_UNCHANGED, alpha dropped (grey +
// alpha, which OpenCV gives as four channels, kept as its grey channel).
cv::Mat OpenCvPixels(const std::vector<unsigned char>& bytes, bool grey_alpha) {
  cv::Mat m = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  if (m.channels() == 4) {
    if (grey_alpha) {
      cv::extractChannel(m, m, 0);
    } else {
      cv::cvtColor(m, m, cv::COLOR_BGRA2BGR);
    }
  }
  return m;
}

void ExpectEqualImages(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.type(), b.type());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

// A PNG written by libpng itself, for the layouts OpenCV's encoder does not write: palettes
// (with transparency), grey of 2 and 4 bits, grey + alpha, Adam7 interlacing.
// `filters`: libpng's PNG_FILTER_* flags it may choose among for each row (0: its default);
// `idat_bytes`: the size of its IDAT chunks (0: libpng's 8 KB).
std::vector<unsigned char> LibpngFile(int width, int height, int bit_depth, int color_type,
                                      bool interlaced, const std::vector<unsigned char>& data,
                                      bool palette_alpha = false, int filters = 0,
                                      std::size_t idat_bytes = 0) {
  std::vector<unsigned char> out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep d, png_size_t n) {
        auto* o = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(p));
        o->insert(o->end(), d, d + n);
      },
      nullptr);
  if (filters != 0) png_set_filter(png, PNG_FILTER_TYPE_BASE, filters);
  if (idat_bytes != 0) png_set_compression_buffer_size(png, idat_bytes);
  png_set_IHDR(png, info, width, height, bit_depth, color_type,
               interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (color_type == PNG_COLOR_TYPE_PALETTE) {
    png_color palette[16];
    for (int i = 0; i < 16; ++i)
      palette[i] = {static_cast<png_byte>(i * 16), static_cast<png_byte>(255 - i * 15),
                    static_cast<png_byte>(i * 7)};
    png_set_PLTE(png, info, palette, 16);
    if (palette_alpha) {
      png_byte alpha[16];
      for (int i = 0; i < 16; ++i) alpha[i] = static_cast<png_byte>(i * 17);
      png_set_tRNS(png, info, alpha, 16, nullptr);
    }
  }
  png_write_info(png, info);
  const std::size_t row = png_get_rowbytes(png, info);
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(data.data() + row * y);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

TEST(DecodePng, SamePixelsAsOpenCvForEveryLayout) {
  struct Case {
    std::string name;
    std::vector<unsigned char> bytes;
    bool grey_alpha;
  };
  std::vector<Case> cases;
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    std::vector<unsigned char> bytes;
    ASSERT_TRUE(cv::imencode(".png", Random(23, 37, type, type), bytes));
    cases.push_back({"OpenCV " + cv::typeToString(type), bytes, false});
  }
  std::vector<unsigned char> bilevel;
  ASSERT_TRUE(
      cv::imencode(".png", Random(9, 21, CV_8UC1, 5) > 128, bilevel, {cv::IMWRITE_PNG_BILEVEL, 1}));
  cases.push_back({"1-bit grey", bilevel, false});
  const int w = 19, h = 11;
  cv::RNG rng(4);
  auto bytes_of = [&](std::size_t n, int max) {
    std::vector<unsigned char> v(n);
    for (auto& b : v) b = static_cast<unsigned char>(rng.uniform(0, max));
    return v;
  };
  cases.push_back(
      {"palette", LibpngFile(w, h, 8, PNG_COLOR_TYPE_PALETTE, false, bytes_of(w * h, 16)), false});
  cases.push_back({"palette + tRNS",
                   LibpngFile(w, h, 8, PNG_COLOR_TYPE_PALETTE, false, bytes_of(w * h, 16), true),
                   false});
  cases.push_back({"4-bit grey",
                   LibpngFile(w, h, 4, PNG_COLOR_TYPE_GRAY, false, bytes_of((w + 1) / 2 * h, 256)),
                   false});
  cases.push_back({"2-bit grey",
                   LibpngFile(w, h, 2, PNG_COLOR_TYPE_GRAY, false, bytes_of((w + 3) / 4 * h, 256)),
                   false});
  cases.push_back({"grey + alpha 8",
                   LibpngFile(w, h, 8, PNG_COLOR_TYPE_GRAY_ALPHA, false, bytes_of(w * h * 2, 256)),
                   true});
  cases.push_back({"grey + alpha 16",
                   LibpngFile(w, h, 16, PNG_COLOR_TYPE_GRAY_ALPHA, false, bytes_of(w * h * 4, 256)),
                   true});
  cases.push_back({"interlaced RGB",
                   LibpngFile(w, h, 8, PNG_COLOR_TYPE_RGB, true, bytes_of(w * h * 3, 256)), false});
  cases.push_back({"interlaced 16-bit grey",
                   LibpngFile(w, h, 16, PNG_COLOR_TYPE_GRAY, true, bytes_of(w * h * 2, 256)),
                   false});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    cv::Mat got;
    std::string why;
    ASSERT_TRUE(DecodePng(c.bytes, got, why)) << why;
    ExpectEqualImages(got, OpenCvPixels(c.bytes, c.grey_alpha));
  }
}

// 8-bit PNGs that are not interlaced are decoded from their whole zlib stream, with the
// filters undone in the program: every filter type alone and libpng's own choice per row, for
// each layout of 8-bit samples, sizes from one pixel to rows longer than zlib's fast loop
// needs, one IDAT chunk and many, against OpenCV's decoder (libpng).
TEST(DecodePng, EveryFilterOfEightBitLayoutsAsOpenCv) {
  const int kFilters[] = {PNG_FILTER_NONE, PNG_FILTER_SUB,   PNG_FILTER_UP,
                          PNG_FILTER_AVG,  PNG_FILTER_PAETH, PNG_ALL_FILTERS};
  const int kColours[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                          PNG_COLOR_TYPE_RGB_ALPHA};
  const cv::Size kSizes[] = {{1, 1}, {3, 2}, {64, 32}, {301, 7}};
  cv::RNG rng(11);
  for (const int colour : kColours)
    for (const cv::Size size : kSizes)
      for (const int filters : kFilters)
        for (const std::size_t idat : {std::size_t{0}, std::size_t{64}}) {
          const int channels = colour == PNG_COLOR_TYPE_GRAY         ? 1
                               : colour == PNG_COLOR_TYPE_GRAY_ALPHA ? 2
                               : colour == PNG_COLOR_TYPE_RGB        ? 3
                                                                     : 4;
          // Smooth rows with noise, so that every filter is worth choosing somewhere.
          std::vector<unsigned char> data(static_cast<std::size_t>(size.area()) * channels);
          for (std::size_t i = 0; i < data.size(); ++i)
            data[i] = static_cast<unsigned char>((i * 7 / 3) % 256 + rng.uniform(0, 9));
          SCOPED_TRACE("colour " + std::to_string(colour) + " size " + std::to_string(size.width) +
                       "x" + std::to_string(size.height) + " filters " + std::to_string(filters) +
                       " idat " + std::to_string(idat));
          const std::vector<unsigned char> bytes =
              LibpngFile(size.width, size.height, 8, colour, false, data, false, filters, idat);
          cv::Mat got;
          std::string why;
          ASSERT_TRUE(DecodePng(bytes, got, why)) << why;
          ExpectEqualImages(got, OpenCvPixels(bytes, colour == PNG_COLOR_TYPE_GRAY_ALPHA));
        }
}

// Image data that is not the image's, in chunks whose CRCs match: a filter type that does not
// exist, and a zlib stream one row short. Neither decoder takes it.
TEST(DecodePng, ImageDataThatIsNotTheImagesIsRefused) {
  const int w = 5, h = 4;
  std::vector<unsigned char> data(w * h, 100);
  // A file of libpng's with its IDAT chunk replaced by one holding `filtered` (filter-type
  // byte and bytes of each row) in a stored zlib stream (no compression: header, one final
  // stored block, Adler-32), with the CRC computed bit by bit (ISO 3309).
  const auto be32 = [](std::vector<unsigned char>& v, std::uint32_t x) {
    for (int k = 3; k >= 0; --k) v.push_back(static_cast<unsigned char>(x >> (8 * k)));
  };
  const auto file_of = [&](const std::vector<unsigned char>& filtered) {
    const std::vector<unsigned char> png = LibpngFile(w, h, 8, PNG_COLOR_TYPE_GRAY, false, data);
    const std::size_t idat = 8 + 25;  // after the signature and the IHDR chunk
    const std::size_t length = (std::size_t{png[idat]} << 24) | (std::size_t{png[idat + 1]} << 16) |
                               (std::size_t{png[idat + 2]} << 8) | png[idat + 3];
    const std::size_t n = filtered.size();
    std::vector<unsigned char> zlib = {0x78,
                                       0x01,
                                       0x01,
                                       static_cast<unsigned char>(n & 0xFF),
                                       static_cast<unsigned char>(n >> 8),
                                       static_cast<unsigned char>(~n & 0xFF),
                                       static_cast<unsigned char>((~n >> 8) & 0xFF)};
    zlib.insert(zlib.end(), filtered.begin(), filtered.end());
    std::uint32_t a = 1, b = 0;
    for (const unsigned char c : filtered) {
      a = (a + c) % 65521;
      b = (b + a) % 65521;
    }
    be32(zlib, (b << 16) | a);
    std::vector<unsigned char> chunk;
    be32(chunk, static_cast<std::uint32_t>(zlib.size()));
    chunk.insert(chunk.end(), {'I', 'D', 'A', 'T'});
    chunk.insert(chunk.end(), zlib.begin(), zlib.end());
    std::uint32_t crc = 0xFFFFFFFFu;
    for (std::size_t i = 4; i < chunk.size(); ++i) {
      crc ^= chunk[i];
      for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    be32(chunk, ~crc);
    std::vector<unsigned char> out(png.begin(), png.begin() + idat);
    out.insert(out.end(), chunk.begin(), chunk.end());
    out.insert(out.end(), png.begin() + idat + 12 + length, png.end());
    return out;
  };
  std::vector<unsigned char> rows;
  for (int y = 0; y < h; ++y) {
    rows.push_back(0);  // filter None
    rows.insert(rows.end(), w, 100);
  }
  cv::Mat got;
  std::string why;
  ASSERT_TRUE(DecodePng(file_of(rows), got, why)) << why;  // the stored stream itself is sound
  ExpectEqualImages(got, cv::Mat(h, w, CV_8UC1, cv::Scalar(100)));
  std::vector<unsigned char> bad_filter = rows;
  bad_filter[(w + 1) * 2] = 9;  // third row: filter type 9
  got.release();
  EXPECT_FALSE(DecodePng(file_of(bad_filter), got, why));
  EXPECT_TRUE(got.empty());
  std::vector<unsigned char> short_rows(rows.begin(), rows.end() - (w + 1));
  got.release();
  EXPECT_FALSE(DecodePng(file_of(short_rows), got, why));
  EXPECT_TRUE(got.empty());
}

// The frames of the real data sets (grey KITTI and EuRoC frames, RGB Nordland and Sussex
// panoramas, every one written by another encoder than libpng's defaults here), decoded from
// their whole stream, against OpenCV's decoder: every tenth file of each folder.
TEST(DecodePng, RealFramesAsOpenCv) {
  const std::string root = testing::DatasetsDir();
  if (!std::filesystem::is_directory(root)) GTEST_SKIP() << "no ../shared/datasets";
  int compared = 0;
  for (const char* folder :
       {"kitti00_first1700", "euroc_stereo_pairs", "nordland_trimmed", "sussex_panoramas"}) {
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::recursive_directory_iterator(root + "/" + folder))
      if (e.path().extension() == ".png") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    for (std::size_t i = 0; i < files.size(); i += 10) {
      SCOPED_TRACE(files[i]);
      std::ifstream in(files[i], std::ios::binary);
      const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                             std::istreambuf_iterator<char>());
      cv::Mat got;
      std::string why;
      ASSERT_TRUE(DecodePng(bytes, got, why)) << why;
      ExpectEqualImages(got, OpenCvPixels(bytes, false));
      ++compared;
    }
  }
  EXPECT_GT(compared, 500);
}

TEST(DecodePng, DamagedDataIsRefusedWithAReason) {
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(cv::imencode(".png", Random(40, 40, CV_8UC3, 1), bytes));
  bytes.resize(bytes.size() / 2);
  cv::Mat got;
  std::string why;
  EXPECT_FALSE(DecodePng(bytes, got, why));
  EXPECT_FALSE(why.empty());
  EXPECT_TRUE(got.empty());
}

// Filtered in bands of rows in parallel, read back by OpenCV (libpng) pixel for pixel, for
// every type the exports write and for images of one pixel, one row, one column, odd widths,
// one band and many.
TEST(EncodePngFile, OpenCvReadsBackTheSamePixels) {
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    for (const cv::Size size : {cv::Size(1, 1), cv::Size(37, 5), cv::Size(9, 1), cv::Size(1, 9),
                                cv::Size(130, 301), cv::Size(3, 129)}) {
      SCOPED_TRACE(cv::typeToString(type) + " " + std::to_string(size.width) + "x" +
                   std::to_string(size.height));
      const cv::Mat image = Random(size.height, size.width, type, size.area());
      for (int threads : {1, 2, 3}) {
        const std::string file = EncodePngFile(image, threads);
        const std::vector<unsigned char> bytes(file.begin(), file.end());
        ExpectEqualImages(cv::imdecode(bytes, cv::IMREAD_UNCHANGED), image);
      }
    }
  }
  EXPECT_THROW(EncodePngFile(cv::Mat(3, 3, CV_32F)), std::logic_error);
  EXPECT_THROW(EncodePngFile(cv::Mat()), std::logic_error);
}

std::uint32_t BigEndian(const std::string& s, std::size_t at) {
  return (std::uint32_t{static_cast<unsigned char>(s[at])} << 24) |
         (std::uint32_t{static_cast<unsigned char>(s[at + 1])} << 16) |
         (std::uint32_t{static_cast<unsigned char>(s[at + 2])} << 8) |
         std::uint32_t{static_cast<unsigned char>(s[at + 3])};
}

// A file whose compressed rows fill several IDAT chunks (noise does not compress) and a smooth
// one like a matrix image: the chunks are IHDR, IDATs of at most 1 MiB, IEND, and both libpng
// through OpenCV and the program's own decoder (libpng too) give the pixels back.
TEST(EncodePngFile, SeveralIdatChunksDecodeToTheSamePixels) {
  cv::Mat3b smooth(1000, 1001);
  for (int y = 0; y < smooth.rows; ++y)
    for (int x = 0; x < smooth.cols; ++x)
      smooth(y, x) = cv::Vec3b(static_cast<std::uint8_t>(std::abs(x - y) / 4),
                               static_cast<std::uint8_t>(x * 255 / 1000), 40);
  for (const cv::Mat& image : {Random(700, 901, CV_8UC3, 7), cv::Mat(smooth)}) {
    const std::string file = EncodePngFile(image);
    std::vector<std::string> types;
    std::size_t at = 8;
    while (at + 12 <= file.size()) {
      const std::uint32_t length = BigEndian(file, at);
      types.push_back(file.substr(at + 4, 4));
      if (types.back() == "IDAT") {
        EXPECT_LE(length, 1u << 20);
      }
      at += 12 + length;
    }
    EXPECT_EQ(at, file.size());
    ASSERT_GE(types.size(), 3u);
    EXPECT_EQ(types.front(), "IHDR");
    EXPECT_EQ(types.back(), "IEND");
    const std::size_t idats = types.size() - 2;
    EXPECT_EQ(std::count(types.begin(), types.end(), "IDAT"), static_cast<long>(idats));
    if (image.data != smooth.data) {
      EXPECT_GE(idats, 2u);  // the noise
    }
    const std::vector<unsigned char> bytes(file.begin(), file.end());
    ExpectEqualImages(cv::imdecode(bytes, cv::IMREAD_UNCHANGED), image);
    cv::Mat decoded;
    std::string why;
    ASSERT_TRUE(DecodePng(bytes, decoded, why)) << why;
    ExpectEqualImages(decoded, image);
  }
}

// The first bytes decide the decoder: sound PNG and JPEG in the program (grey + alpha said),
// damage named before any decoder sees it, and anything unknown left to OpenImageIO (empty).
TEST(DecodeCommonFormat, RecognisesTheFormatsAndNamesTheDamage) {
  const cv::Mat grey = Random(9, 13, CV_8UC1, 5);
  std::vector<unsigned char> png;
  ASSERT_TRUE(cv::imencode(".png", grey, png));
  bool grey_alpha = true;
  ExpectEqualImages(DecodeCommonFormat(png, grey_alpha), grey);
  EXPECT_FALSE(grey_alpha);

  const std::vector<unsigned char> data(4 * 3 * 2, 200);
  const std::vector<unsigned char> ga = LibpngFile(4, 3, 8, PNG_COLOR_TYPE_GRAY_ALPHA, false, data);
  const cv::Mat two = DecodeCommonFormat(ga, grey_alpha);
  EXPECT_FALSE(two.empty());
  EXPECT_TRUE(grey_alpha);

  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", grey, jpeg));
  const cv::Mat decoded = DecodeCommonFormat(jpeg, grey_alpha);
  EXPECT_EQ(decoded.type(), CV_8UC1);
  EXPECT_EQ(decoded.size(), grey.size());

  const std::vector<unsigned char> cut(png.begin(), png.end() - 20);
  try {
    DecodeCommonFormat(cut, grey_alpha);
    ADD_FAILURE() << "a truncated PNG was decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated PNG"), std::string::npos) << e.what();
  }
  const std::vector<unsigned char> jpeg_cut(jpeg.begin(), jpeg.begin() + jpeg.size() / 2);
  EXPECT_TRUE(DecodeCommonFormat(jpeg_cut, grey_alpha).empty());  // no end marker: OpenImageIO
  const std::string text = "plain text, not an image at all";
  EXPECT_TRUE(DecodeCommonFormat({text.begin(), text.end()}, grey_alpha).empty());
}

}  // namespace
}  // namespace openable
