#include "OpenABLE/io/image_codec.h"

#include <jpeglib.h>  // after <cstdio>: it uses FILE and size_t without including them
#include <libdeflate.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/io/module_api.h"

namespace openable {
namespace {

// ---------------------------------------------------------------------------------------------
// Decoding (libpng). libpng reports errors by longjmp to the setjmp of the caller; the functions
// holding a setjmp below keep no C++ object with a destructor alive across libpng's calls.

struct Reader {
  const unsigned char* data = nullptr;
  std::size_t size = 0, pos = 0;
  char error[200] = {0};
};

void ReadBytes(png_structp png, png_bytep out, png_size_t n) {
  Reader* r = static_cast<Reader*>(png_get_io_ptr(png));
  if (r->size - r->pos < n) png_error(png, "the file ends inside its image data");
  std::memcpy(out, r->data + r->pos, n);
  r->pos += n;
}

void OnError(png_structp png, png_const_charp message) {
  Reader* r = static_cast<Reader*>(png_get_error_ptr(png));
  std::snprintf(r->error, sizeof r->error, "%s", message);
  png_longjmp(png, 1);
}

void OnWarning(png_structp, png_const_charp) {}  // e.g. sRGB profile notes: not errors

bool IsLittleEndian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// Reads the header and sets the transformations; false on a libpng error.
bool ReadHeader(png_structp png, png_infop info, int& width, int& height, int& channels, int& depth,
                std::size_t& row_bytes) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int color = png_get_color_type(png, info);
  const int bits = png_get_bit_depth(png, info);
  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color & PNG_COLOR_MASK_COLOR) == 0 && bits < 8) png_set_expand_gray_1_2_4_to_8(png);
  png_set_strip_alpha(png);
  if (bits == 16 && IsLittleEndian()) png_set_swap(png);  // cv::Mat holds native uint16
  if ((color & PNG_COLOR_MASK_COLOR) != 0) png_set_bgr(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  width = static_cast<int>(png_get_image_width(png, info));
  height = static_cast<int>(png_get_image_height(png, info));
  channels = png_get_channels(png, info);
  depth = png_get_bit_depth(png, info);
  row_bytes = png_get_rowbytes(png, info);
  return true;
}

bool ReadRows(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

// ---------------------------------------------------------------------------------------------
// Encoding (libdeflate). Written here rather than through libpng's writer, which compresses
// with zlib on one thread: the PNG container itself is a few fixed chunks, the rows are
// filtered in parallel, and libdeflate compresses them.

void Put32(std::string& out, std::uint32_t v) {
  const char b[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                     static_cast<char>(v >> 8), static_cast<char>(v)};
  out.append(b, 4);
}

// A chunk of `size` bytes of `data`: length, type, data, CRC-32 of the type and the data.
void PutChunk(std::string& out, const char type[4], const char* data, std::size_t size) {
  Put32(out, static_cast<std::uint32_t>(size));
  const std::size_t start = out.size();
  out.append(type, 4);
  out.append(data, size);
  Put32(out, libdeflate_crc32(0, out.data() + start, out.size() - start));
}

// One row in PNG sample order: RGB(A) from BGR(A), 16-bit values big-endian.
void SwapToPng(const unsigned char* src, unsigned char* raw, int cols, int channels, int sample) {
  for (int x = 0; x < cols; ++x) {
    for (int c = 0; c < channels; ++c) {
      const int from = channels >= 3 && c < 3 ? 2 - c : c;
      const unsigned char* s = src + (static_cast<std::size_t>(x) * channels + from) * sample;
      unsigned char* d = raw + (static_cast<std::size_t>(x) * channels + c) * sample;
      if (sample == 1) {
        d[0] = s[0];
      } else {
        std::uint16_t v = 0;
        std::memcpy(&v, s, 2);
        d[0] = static_cast<unsigned char>(v >> 8);
        d[1] = static_cast<unsigned char>(v & 0xFF);
      }
    }
  }
}

// Rows [y0, y1) of `image` filtered (Sub: each byte minus the byte one pixel to its left, 0 for
// the first pixel) into `out`, one filter-type byte then the row's bytes for each row: the
// data that the zlib stream of the IDAT chunks holds, in PNG sample order (RGB(A) from
// BGR(A), 16-bit values big-endian). 8-bit grey and BGR, the matrix images, are filtered
// straight from the image (a third of the time of going through a copy in PNG order); the
// other types through SwapToPng.
void FilterRows(const cv::Mat& image, int y0, int y1, unsigned char* out) {
  const int channels = image.channels();
  const int sample = image.depth() == CV_16U ? 2 : 1;
  const int bpp = channels * sample;  // bytes per pixel
  const std::size_t row_size = static_cast<std::size_t>(image.cols) * bpp;
  std::vector<unsigned char> raw;
  for (int y = y0; y < y1; ++y) {
    const unsigned char* src = image.ptr<unsigned char>(y);
    unsigned char* row = out + (row_size + 1) * static_cast<std::size_t>(y - y0);
    row[0] = 1;  // filter type Sub
    unsigned char* d = row + 1;
    if (bpp == 1) {
      d[0] = src[0];
      for (std::size_t i = 1; i < row_size; ++i)
        d[i] = static_cast<unsigned char>(src[i] - src[i - 1]);
    } else if (sample == 1 && channels == 3) {
      d[0] = src[2];
      d[1] = src[1];
      d[2] = src[0];
      for (std::size_t i = 3; i < row_size; i += 3) {
        d[i] = static_cast<unsigned char>(src[i + 2] - src[i - 1]);
        d[i + 1] = static_cast<unsigned char>(src[i + 1] - src[i - 2]);
        d[i + 2] = static_cast<unsigned char>(src[i] - src[i - 3]);
      }
    } else {
      raw.resize(row_size);
      SwapToPng(src, raw.data(), image.cols, channels, sample);
      const std::size_t first = std::min(row_size, static_cast<std::size_t>(bpp));
      for (std::size_t i = 0; i < first; ++i) d[i] = raw[i];
      for (std::size_t i = first; i < row_size; ++i)
        d[i] = static_cast<unsigned char>(raw[i] - raw[i - bpp]);
    }
  }
}

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

// libdeflate's level for the PNG files: level 1 writes files half the size of zlib's level 1 in
// a fraction of its time, and higher levels cost much more time for files a few percent
// smaller (docs/benchmarks.md, "Exports").
constexpr int kDeflateLevel = 1;

// ---------------------------------------------------------------------------------------------
// Recognising the formats, checking PNG chunks and JPEG ends, decoding JPEG (libjpeg).

// CRC-32 of PNG chunks (ISO 3309), libdeflate's.
std::uint32_t Crc32(const unsigned char* data, std::size_t size) {
  return libdeflate_crc32(0, data, size);
}

std::uint32_t BigEndian32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

enum class PngCheck { kNotPng, kSound, kTruncated, kDamaged };

// libpng prints "libpng error: ..." on stderr (through OpenCV, which keeps libpng's default
// handlers) before any decoder sees the error, and truncated files are the common corruption
// (an interrupted copy). So a file that starts as a PNG has its chunk layout walked and every
// chunk's CRC checked before decoding. kTruncated comes with the reason in `why`; kDamaged
// (a CRC mismatch) also comes with its reason: libpng would print its own complaint first,
// whichever library calls it. A chunk without a name is left to OpenImageIO to explain.
PngCheck CheckPng(const std::vector<unsigned char>& bytes, std::string& why) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 || !std::equal(kSignature, kSignature + 8, bytes.begin())) {
    return PngCheck::kNotPng;
  }
  const std::uint64_t size = bytes.size();
  std::uint64_t pos = 8;
  while (true) {
    if (pos + 8 > size) {
      why = "truncated PNG: the file ends before its IEND chunk";
      return PngCheck::kTruncated;
    }
    const std::uint64_t length = BigEndian32(&bytes[pos]);
    const std::string type(reinterpret_cast<const char*>(&bytes[pos + 4]), 4);
    const bool named = std::all_of(type.begin(), type.end(), [](char c) {
      return std::isalpha(static_cast<unsigned char>(c)) != 0;
    });
    if (!named) return PngCheck::kDamaged;
    if (pos + 12 + length > size) {
      why = "truncated PNG: the file ends inside its " + type + " chunk";
      return PngCheck::kTruncated;
    }
    if (Crc32(&bytes[pos + 4], 4 + length) != BigEndian32(&bytes[pos + 8 + length])) {
      why = "damaged PNG: the checksum (CRC) of its " + type + " chunk does not match its data";
      return PngCheck::kDamaged;
    }
    if (type == "IEND") return PngCheck::kSound;
    pos += 12 + length;  // length, type, data, CRC
  }
}

// True when a JPEG ends with its EOI marker (FF D9), allowing a little padding after it.
// libjpeg only warns about a missing end (on stderr) and fills the rest with grey.
bool JpegHasEnd(const std::vector<unsigned char>& bytes) {
  const std::size_t stop = bytes.size() > 64 ? bytes.size() - 64 : 0;
  for (std::size_t i = bytes.size(); i >= stop + 2; --i) {
    if (bytes[i - 2] == 0xFF && bytes[i - 1] == 0xD9) return true;
  }
  return false;
}

// Frames are resized to Patch_size before they are described, so an image of hundreds of
// megapixels only costs time and memory (4 bytes a pixel once converted to float;
// docs/robustness.md, "Image sizes"): such images are refused before decoding.
constexpr std::uint64_t kMaxPixels = 100'000'000;

void CheckPixelCount(std::uint64_t width, std::uint64_t height) {
  if (width * height > kMaxPixels)
    throw InputError("is " + std::to_string(width) + "x" + std::to_string(height) + " (" +
                     std::to_string(width * height / 1'000'000) +
                     " megapixels); expected at "
                     "most " +
                     std::to_string(kMaxPixels / 1'000'000) +
                     " megapixels (frames are "
                     "resized to Patch_size: scale the images down first)");
}

// The size in a JPEG's start-of-frame segment; false when the segments before it do not parse.
bool JpegSize(const std::vector<unsigned char>& bytes, std::uint32_t& width,
              std::uint32_t& height) {
  std::size_t pos = 2;
  while (pos + 9 <= bytes.size() && bytes[pos] == 0xFF) {
    const unsigned char marker = bytes[pos + 1];
    const std::size_t length = (std::size_t{bytes[pos + 2]} << 8) | bytes[pos + 3];
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      height = (std::uint32_t{bytes[pos + 5]} << 8) | bytes[pos + 6];
      width = (std::uint32_t{bytes[pos + 7]} << 8) | bytes[pos + 8];
      return true;
    }
    if (marker == 0xDA || length < 2) return false;  // the scan starts before any frame header
    pos += 2 + length;
  }
  return false;
}

// libjpeg's error manager for DecodeJpeg: the first warning or error ends the decoding with
// libjpeg's own text, instead of a line on stderr (warnings) or exit() (errors).
struct JpegErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void JpegStop(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

void JpegMessage(j_common_ptr cinfo, int level) {
  if (level < 0) JpegStop(cinfo);  // a warning: "Corrupt JPEG data: ...", "Premature end ..."
}

// Decodes a JPEG of 1 or 3 components into CV_8UC1 or CV_8UC3 (BGR) with libjpeg, which
// OpenCV uses too: OpenCV lets libjpeg print warnings about damaged data on stderr and returns
// the image with the damage filled in. Returns false with libjpeg's message in `why` at the
// first warning or error; leaves `image` empty for other colour spaces (CMYK: OpenCV's).
bool DecodeJpeg(const std::vector<unsigned char>& bytes, cv::Mat& image, std::string& why) {
  jpeg_decompress_struct cinfo;
  JpegErrors errors;
  cinfo.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = JpegStop;
  errors.manager.emit_message = JpegMessage;
  if (setjmp(errors.jump) != 0) {
    jpeg_destroy_decompress(&cinfo);
    image.release();
    why = std::string("damaged JPEG: ") + errors.message;
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, const_cast<unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&cinfo, TRUE);
  if (cinfo.num_components == 1 || cinfo.num_components == 3) {
    cinfo.out_color_space = cinfo.num_components == 1 ? JCS_GRAYSCALE : JCS_EXT_BGR;
    jpeg_start_decompress(&cinfo);
    image.create(static_cast<int>(cinfo.output_height), static_cast<int>(cinfo.output_width),
                 cinfo.output_components == 1 ? CV_8UC1 : CV_8UC3);
    while (cinfo.output_scanline < cinfo.output_height) {
      JSAMPROW row = image.ptr<unsigned char>(static_cast<int>(cinfo.output_scanline));
      jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
  }
  jpeg_destroy_decompress(&cinfo);
  return true;
}

// The maximum value of a binary or plain PGM/PPM header, or 0 when it cannot be read (or the
// file is a bitmap, P1/P4, which has none).
int PnmMaxValue(const std::vector<unsigned char>& bytes) {
  std::size_t pos = 2;
  int values[3] = {0, 0, 0};
  for (int& v : values) {
    while (pos < bytes.size()) {  // blanks and comments
      if (bytes[pos] == '#') {
        while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
      } else if (std::isspace(bytes[pos]) != 0) {
        ++pos;
      } else {
        break;
      }
    }
    if (pos >= bytes.size() || std::isdigit(bytes[pos]) == 0) return 0;
    while (pos < bytes.size() && std::isdigit(bytes[pos]) != 0 && v < 1000000) {
      v = v * 10 + (bytes[pos++] - '0');
    }
  }
  return values[2];
}

// The PNG filters undone in place on `rows` rows of `row_bytes` bytes, each after its
// filter-type byte (PNG specification, section 9), `bpp` bytes a pixel. False on an unknown
// filter type.
bool Unfilter(unsigned char* data, int rows, std::size_t row_bytes, int bpp) {
  const std::vector<unsigned char> zeros(row_bytes, 0);
  const unsigned char* up = zeros.data();
  const std::size_t step = static_cast<std::size_t>(bpp);
  for (int y = 0; y < rows; ++y) {
    unsigned char* row = data + static_cast<std::size_t>(y) * (row_bytes + 1);
    unsigned char* x = row + 1;
    // The bytes one pixel to the left, in this row and the one above (0 left of the first).
    const auto left = [&](std::size_t i) { return i >= step ? x[i - step] : 0; };
    const auto up_left = [&](std::size_t i) { return i >= step ? up[i - step] : 0; };
    switch (row[0]) {
      case 0:  // None
        break;
      case 1:  // Sub
        for (std::size_t i = step; i < row_bytes; ++i)
          x[i] = static_cast<unsigned char>(x[i] + x[i - step]);
        break;
      case 2:  // Up
        for (std::size_t i = 0; i < row_bytes; ++i) x[i] = static_cast<unsigned char>(x[i] + up[i]);
        break;
      case 3:  // Average
        for (std::size_t i = 0; i < row_bytes; ++i)
          x[i] = static_cast<unsigned char>(x[i] + ((left(i) + up[i]) >> 1));
        break;
      case 4:  // Paeth
        for (std::size_t i = 0; i < row_bytes; ++i) {
          const int a = left(i), b = up[i], c = up_left(i);
          const int p = a + b - c;
          const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          const int predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          x[i] = static_cast<unsigned char>(x[i] + predictor);
        }
        break;
      default:
        return false;
    }
    up = x;
  }
  return true;
}

// The common PNG of frames, 8-bit samples (grey, grey + alpha, RGB, RGBA) not interlaced,
// decoded with its image data decompressed whole by libdeflate and the rows unfiltered here,
// rather than by libpng, which inflates into a buffer of one row at a time: rows shorter than
// 258 bytes (64 x 32 frames, the size Nordland is commonly used at) keep zlib's inflate out of
// its fast loop (docs/benchmarks.md, "PNG frames decoded whole"). The pixels are libpng's: alpha
// dropped, BGR order. The five filters are undone here because libpng offers no call that unfilters
// a buffer it did not inflate itself. Returns false, leaving the file to libpng, for any other
// layout, a chunk whose CRC does not match, an unknown critical chunk, or image data that is not
// exactly the image's: libpng then decodes the file or gives its own reason.
bool DecodeWholeStream(const std::vector<unsigned char>& bytes, cv::Mat& image) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 + 25 || !std::equal(kSignature, kSignature + 8, bytes.begin())) return false;
  std::uint32_t width = 0, height = 0;
  int channels = 0;
  std::vector<unsigned char> stream;
  const unsigned char* single = nullptr;  // the data of the only IDAT chunk
  std::size_t single_size = 0, idat_chunks = 0;
  std::size_t pos = 8;
  bool end = false;
  while (!end) {
    if (pos + 12 > bytes.size()) return false;
    const std::size_t length = BigEndian32(&bytes[pos]);
    const unsigned char* type = &bytes[pos + 4];
    const unsigned char* data = type + 4;
    if (length > bytes.size() - pos - 12) return false;
    if (Crc32(type, 4 + length) != BigEndian32(data + length)) return false;
    const auto is = [&](const char* name) { return std::memcmp(type, name, 4) == 0; };
    if (pos == 8) {  // IHDR first
      if (!is("IHDR") || length != 13) return false;
      width = BigEndian32(data);
      height = BigEndian32(data + 4);
      const int depth = data[8], colour = data[9];
      channels = colour == 0 ? 1 : colour == 4 ? 2 : colour == 2 ? 3 : colour == 6 ? 4 : 0;
      if (depth != 8 || channels == 0 || data[10] != 0 || data[11] != 0 || data[12] != 0 ||
          width == 0 || height == 0 ||
          static_cast<std::uint64_t>(width) * height > (std::uint64_t{1} << 27))
        return false;  // larger images: libpng, after DecodeCommonFormat's size check
    } else if (is("IDAT")) {
      if (idat_chunks++ == 0) {
        single = data;
        single_size = length;
      } else {
        if (idat_chunks == 2) stream.assign(single, single + single_size);
        stream.insert(stream.end(), data, data + length);
      }
    } else if (is("IEND")) {
      end = true;
    } else if ((type[0] & 0x20) == 0 && !is("PLTE")) {
      return false;  // a critical chunk this decoder does not know
    }
    pos += 12 + length;
  }
  if (idat_chunks == 0) return false;
  const std::size_t row_bytes = static_cast<std::size_t>(width) * channels;
  const std::size_t size = (row_bytes + 1) * height;
  // Deflate expands at most about 1032 to 1: a header claiming more than its data can hold is
  // left to libpng, which refuses it, rather than given a buffer of that size.
  const std::size_t compressed = idat_chunks == 1 ? single_size : stream.size();
  if (size / 1032 > compressed + 64) return false;
  thread_local std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)>
      decompressor(libdeflate_alloc_decompressor(), libdeflate_free_decompressor);
  if (decompressor == nullptr) return false;
  std::unique_ptr<unsigned char[]> raw(new unsigned char[size]);
  std::size_t written = 0;
  const bool whole = idat_chunks == 1;
  if (libdeflate_zlib_decompress(decompressor.get(), whole ? single : stream.data(),
                                 whole ? single_size : stream.size(), raw.get(), size,
                                 &written) != LIBDEFLATE_SUCCESS ||
      written != size)
    return false;
  if (!Unfilter(raw.get(), static_cast<int>(height), row_bytes, channels)) return false;
  cv::Mat out(static_cast<int>(height), static_cast<int>(width), channels >= 3 ? CV_8UC3 : CV_8UC1);
  for (int y = 0; y < out.rows; ++y) {
    const unsigned char* in = raw.get() + static_cast<std::size_t>(y) * (row_bytes + 1) + 1;
    unsigned char* o = out.ptr(y);
    if (channels == 1) {
      std::memcpy(o, in, row_bytes);
    } else if (channels == 2) {
      for (std::uint32_t x = 0; x < width; ++x) o[x] = in[2 * x];
    } else {
      for (std::uint32_t x = 0; x < width; ++x, o += 3, in += channels) {
        o[0] = in[2];
        o[1] = in[1];
        o[2] = in[0];
      }
    }
  }
  image = out;
  return true;
}

}  // namespace

bool DecodePng(const std::vector<unsigned char>& bytes, cv::Mat& image, std::string& why) {
  if (DecodeWholeStream(bytes, image)) return true;
  Reader reader;
  reader.data = bytes.data();
  reader.size = bytes.size();
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &reader, OnError, OnWarning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_read_struct(&png, &info, nullptr);
    why = "libpng cannot start (out of memory)";
    return false;
  }
  png_set_read_fn(png, &reader, ReadBytes);
  int width = 0, height = 0, channels = 0, depth = 0;
  std::size_t row_bytes = 0;
  bool ok = ReadHeader(png, info, width, height, channels, depth, row_bytes);
  if (ok && ((channels != 1 && channels != 3) || (depth != 8 && depth != 16) || width <= 0 ||
             height <= 0)) {
    std::snprintf(reader.error, sizeof reader.error, "unexpected layout after conversion");
    ok = false;
  }
  if (ok) {
    cv::Mat out(height, width, CV_MAKETYPE(depth == 16 ? CV_16U : CV_8U, channels));
    if (row_bytes != out.step[0]) {
      std::snprintf(reader.error, sizeof reader.error, "unexpected row size");
      ok = false;
    } else {
      std::vector<png_bytep> rows(static_cast<std::size_t>(height));
      for (int y = 0; y < height; ++y) rows[static_cast<std::size_t>(y)] = out.ptr(y);
      ok = ReadRows(png, info, rows.data());
      if (ok) image = out;
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!ok) why = reader.error[0] != '\0' ? reader.error : "libpng could not decode it";
  return ok;
}

std::string EncodePngFile(const cv::Mat& image, int threads) {
  const int depth = image.depth(), channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) || (channels != 1 && channels != 3 && channels != 4) ||
      image.empty()) {
    throw std::logic_error(
        "EncodePngFile: expected a non-empty 8- or 16-bit image of 1, 3 or 4 "
        "channels, got " +
        cv::typeToString(image.type()));
  }
  // The filtered rows: bands of 64 rows in parallel, into one buffer (every byte is written).
  const int bpp = channels * (depth == CV_16U ? 2 : 1);
  const std::size_t filtered_row = static_cast<std::size_t>(image.cols) * bpp + 1;
  const std::size_t filtered_size = filtered_row * static_cast<std::size_t>(image.rows);
  const std::unique_ptr<unsigned char[]> filtered(new unsigned char[filtered_size]);
  constexpr int kBandRows = 64;
  const int bands = (image.rows + kBandRows - 1) / kBandRows;
  ParallelFor(bands, threads, [&](int b) {
    FilterRows(image, b * kBandRows, std::min(image.rows, (b + 1) * kBandRows),
               filtered.get() + filtered_row * static_cast<std::size_t>(b) * kBandRows);
  });

  // One zlib stream of all the rows, compressed on one thread: libdeflate compresses a whole
  // buffer into a complete stream whose last block is marked final, and offers no flush, so
  // bands compressed apart could not be joined into the one stream that PNG allows (zlib's
  // sync flush made that possible). It still beats zlib on two cores, and leaves the other
  // core to the exports that run meanwhile (docs/benchmarks.md, "Exports").
  const std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor(
      libdeflate_alloc_compressor(kDeflateLevel));
  if (compressor == nullptr) throw std::runtime_error("PNG encoder: libdeflate cannot start");
  const std::size_t bound = libdeflate_zlib_compress_bound(compressor.get(), filtered_size);
  const std::unique_ptr<char[]> stream(new char[bound]);
  const std::size_t stream_size = libdeflate_zlib_compress(compressor.get(), filtered.get(),
                                                           filtered_size, stream.get(), bound);
  if (stream_size == 0) throw std::runtime_error("PNG encoder: libdeflate failed");

  // The stream in IDAT chunks of at most 1 MiB (a chunk's length must stay below 2^31).
  constexpr std::size_t kIdatBytes = std::size_t{1} << 20;
  const std::size_t idats = (stream_size + kIdatBytes - 1) / kIdatBytes;
  std::string out;
  out.reserve(8 + 25 + stream_size + 12 * idats + 12);
  out.append("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  Put32(header, static_cast<std::uint32_t>(image.cols));
  Put32(header, static_cast<std::uint32_t>(image.rows));
  header += static_cast<char>(depth == CV_16U ? 16 : 8);
  header += static_cast<char>(channels == 1 ? 0 : channels == 3 ? 2 : 6);  // grey, RGB, RGBA
  header += std::string(3, '\0');  // deflate, adaptive filtering, no interlace
  PutChunk(out, "IHDR", header.data(), header.size());
  for (std::size_t at = 0; at < stream_size; at += kIdatBytes)
    PutChunk(out, "IDAT", stream.get() + at, std::min(kIdatBytes, stream_size - at));
  PutChunk(out, "IEND", "", 0);
  return out;
}

cv::Mat DecodeCommonFormat(const std::vector<unsigned char>& bytes, bool& grey_alpha) {
  grey_alpha = false;
  std::string why;
  const PngCheck png = CheckPng(bytes, why);  // before the size check: a cut PNG is short
  if (!why.empty()) throw InputError(why);
  if (bytes.size() < 16) return cv::Mat();
  const bool jpeg = bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  const bool pnm =
      bytes[0] == 'P' && (bytes[1] == '2' || bytes[1] == '3' || bytes[1] == '5' || bytes[1] == '6');
  const bool bmp = bytes[0] == 'B' && bytes[1] == 'M';
  if (!why.empty()) throw InputError(why);
  if (png == PngCheck::kSound) {
    // IHDR colour type 4: grey + alpha. A sound chunk walk does not mean that IHDR comes first
    // (or at all: a signature and IEND are 20 bytes), and the decoders refuse such a file.
    static const unsigned char kIhdr[4] = {'I', 'H', 'D', 'R'};
    const bool ihdr_first = bytes.size() > 25 && std::equal(kIhdr, kIhdr + 4, bytes.begin() + 12);
    if (ihdr_first) CheckPixelCount(BigEndian32(&bytes[16]), BigEndian32(&bytes[20]));
    grey_alpha = ihdr_first && bytes[25] == 4;
  } else if (png == PngCheck::kDamaged || (jpeg && !JpegHasEnd(bytes))) {
    return cv::Mat();
  } else if (pnm) {
    const int max_value = PnmMaxValue(bytes);
    if (max_value != 255 && max_value != 65535) return cv::Mat();
  } else if (!jpeg && !bmp) {
    return cv::Mat();
  }
  if (jpeg) {
    std::uint32_t width = 0, height = 0;
    if (JpegSize(bytes, width, height)) CheckPixelCount(width, height);
    cv::Mat image;
    if (!DecodeJpeg(bytes, image, why)) throw InputError(why);
    if (!image.empty()) return image;
  }
  if (png == PngCheck::kSound) {
    cv::Mat image;
    return DecodePng(bytes, image, why) ? image : cv::Mat();  // libpng's refusal: OpenImageIO
  }
  // PGM/PPM and BMP: OpenCV's imgcodecs, loaded on first use.
  cv::Mat image;
  reinterpret_cast<OpenableCodecsDecode>(ModuleSymbol("codecs", "openable_codecs_decode"))(bytes,
                                                                                           image);
  return image;
}

std::string EncodeJpegFile(const cv::Mat& image, int quality) {
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
    throw std::logic_error("EncodeJpegFile: expected an 8-bit grey or BGR image");
  if (image.empty()) throw std::logic_error("EncodeJpegFile: empty image");
  jpeg_compress_struct cinfo;
  JpegErrors errors;
  cinfo.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = JpegStop;
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  if (setjmp(errors.jump) != 0) {
    jpeg_destroy_compress(&cinfo);
    std::free(buffer);
    throw InputError(std::string("JPEG encoding failed: ") + errors.message);
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = static_cast<JDIMENSION>(image.cols);
  cinfo.image_height = static_cast<JDIMENSION>(image.rows);
  cinfo.input_components = image.channels();
  cinfo.in_color_space = image.channels() == 1 ? JCS_GRAYSCALE : JCS_EXT_BGR;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, std::clamp(quality, 1, 100), TRUE);
  cinfo.optimize_coding = TRUE;  // Huffman tables of the image itself: smaller files
  jpeg_start_compress(&cinfo, TRUE);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row =
        const_cast<unsigned char*>(image.ptr<unsigned char>(static_cast<int>(cinfo.next_scanline)));
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  std::string bytes(reinterpret_cast<const char*>(buffer), size);
  std::free(buffer);
  return bytes;
}

}  // namespace openable
