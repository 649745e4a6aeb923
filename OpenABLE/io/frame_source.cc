#include "OpenABLE/io/frame_source.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <jpeglib.h>
#include <zlib.h>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/io_common.h"
#include "OpenABLE/io/module_api.h"
#include "OpenABLE/io/png_codec.h"

namespace openable {
namespace {

namespace fs = std::filesystem;
using namespace io_internal;

bool IsDigit(char c) { return c >= '0' && c <= '9'; }



std::string JoinSupported() {
  std::string out;
  for (const std::string& e : SupportedImageExtensions()) out += (out.empty() ? "" : ", ") + e;
  return out;
}

// CRC-32 of PNG chunks (ISO 3309), zlib's.
std::uint32_t Crc32(const unsigned char* data, std::size_t size) {
  return static_cast<std::uint32_t>(crc32(0L, data, static_cast<uInt>(size)));
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
// megapixels only costs time and memory (4 bytes a pixel once converted to float; a 20000 x
// 20000 PNG took 10 s and 2 GB per frame): such images are refused before decoding.
constexpr std::uint64_t kMaxPixels = 100'000'000;

void CheckPixelCount(std::uint64_t width, std::uint64_t height) {
  if (width * height > kMaxPixels)
    throw InputError("is " + std::to_string(width) + "x" + std::to_string(height) + " (" +
                     std::to_string(width * height / 1'000'000) + " megapixels); expected at "
                     "most " + std::to_string(kMaxPixels / 1'000'000) + " megapixels (frames are "
                     "resized to Patch_size: scale the images down first)");
}

// The size in a JPEG's start-of-frame segment; false when the segments before it do not parse.
bool JpegSize(const std::vector<unsigned char>& bytes, std::uint32_t& width,
              std::uint32_t& height) {
  std::size_t pos = 2;
  while (pos + 9 <= bytes.size() && bytes[pos] == 0xFF) {
    const unsigned char marker = bytes[pos + 1];
    const std::size_t length = (std::size_t{bytes[pos + 2]} << 8) | bytes[pos + 3];
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                     marker != 0xCC;
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

// Decodes the common formats: PNG whose chunks are sound (libpng, png_codec.h) and JPEG with
// its end marker (libjpeg), both in the program, and binary and plain PGM/PPM of 8 or 16 bits
// and BMP through OpenCV's imgcodecs, a module loaded on first use (module_loader.h). Returns
// an empty Mat for anything else, or when the decoder fails, so that OpenImageIO decodes the
// file or says precisely what is wrong with it.
cv::Mat DecodeCommonFormat(const std::vector<unsigned char>& bytes, bool& grey_alpha) {
  grey_alpha = false;
  std::string why;
  const PngCheck png = CheckPng(bytes, why);  // before the size check: a cut PNG is short
  if (!why.empty()) throw InputError(why);
  if (bytes.size() < 16) return cv::Mat();
  const bool jpeg = bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  const bool pnm = bytes[0] == 'P' && (bytes[1] == '2' || bytes[1] == '3' || bytes[1] == '5' ||
                                       bytes[1] == '6');
  const bool bmp = bytes[0] == 'B' && bytes[1] == 'M';
  if (!why.empty()) throw InputError(why);
  if (png == PngCheck::kSound) {
    // IHDR colour type 4: grey + alpha. A sound chunk walk does not mean that IHDR comes first
    // (or at all: a signature and IEND are 20 bytes), and the decoders refuse such a file.
    static const unsigned char kIhdr[4] = {'I', 'H', 'D', 'R'};
    const bool ihdr_first =
        bytes.size() > 25 && std::equal(kIhdr, kIhdr + 4, bytes.begin() + 12);
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
  reinterpret_cast<OpenableCodecsDecode>(ModuleSymbol("codecs", "openable_codecs_decode"))(
      bytes, image);
  return image;
}

// The decoding shared by ReadImageFile and DecodeImageBytes: DecodeCommonFormat for the common
// formats, else `oiio_fallback` (OpenImageIO on the file or on the bytes). `name` names the
// image in messages.
template <typename Fallback>
cv::Mat DecodeBytes(const std::vector<unsigned char>& bytes, const std::string& name,
                    const Fallback& oiio_fallback) {
  bool grey_alpha = false;
  cv::Mat image;
  try {
    image = DecodeCommonFormat(bytes, grey_alpha);
  } catch (const InputError& e) {
    const std::string what = e.what();  // "is ..." (too large) or the damage found
    throw InputError("image " + Quoted(name) + " " +
                     (what.rfind("is ", 0) == 0 ? what : "cannot be decoded: " + what) + " (" +
                     kExpectedImage + ")");
  }
  const int depth = image.depth();
  if (image.empty() || (depth != CV_8U && depth != CV_16U) || image.channels() == 2) {
    // Everything else (TIFF, damaged files, unusual depths) goes to OpenImageIO.
    return oiio_fallback();
  }
  if (image.channels() == 4) {
    if (grey_alpha) {
      cv::extractChannel(image, image, 0);
    } else {
      cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
    }
  }
  cv::Mat frame;
  image.convertTo(frame, CV_MAKETYPE(CV_32F, image.channels()),
                  depth == CV_8U ? 1.0 / 255.0 : 1.0 / 65535.0);
  return frame;
}

// Frames of an image folder; each Read opens its own file, so reads may run in parallel.
class ImageFolderSource final : public FrameSource {
 public:
  explicit ImageFolderSource(std::vector<std::string> paths) : paths_(std::move(paths)) {}

  int Size() const override { return static_cast<int>(paths_.size()); }

  std::string FrameName(int i) const override {
    CheckIndex(i, Size(), "ImageFolderSource::FrameName");
    return paths_[static_cast<std::size_t>(i)];
  }

  cv::Mat Read(int i) const override {
    CheckIndex(i, Size(), "ImageFolderSource::Read");
    return ReadImageFile(paths_[static_cast<std::size_t>(i)]);
  }

  bool ParallelReads() const override { return true; }

 private:
  std::vector<std::string> paths_;
};

}  // namespace

bool NaturalLess(const std::string& a, const std::string& b) {
  // Both names are read as sequences of tokens: a run of digits (compared by numeric value,
  // which sorts all runs between the characters below '0' and those above '9') or a single
  // other character. Equal token sequences ("a01", "a1") fall back to plain order.
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      std::size_t i_end = i;
      while (i_end < a.size() && IsDigit(a[i_end])) ++i_end;
      std::size_t j_end = j;
      while (j_end < b.size() && IsDigit(b[j_end])) ++j_end;
      // Values of any length: without leading zeros, a shorter run is a smaller number and
      // runs of equal length compare as text.
      std::size_t i_sig = i;
      while (i_sig < i_end && a[i_sig] == '0') ++i_sig;
      std::size_t j_sig = j;
      while (j_sig < j_end && b[j_sig] == '0') ++j_sig;
      const std::size_t a_len = i_end - i_sig;
      const std::size_t b_len = j_end - j_sig;
      if (a_len != b_len) return a_len < b_len;
      const int c = a.compare(i_sig, a_len, b, j_sig, b_len);
      if (c != 0) return c < 0;
      i = i_end;
      j = j_end;
    } else {
      const auto ca = static_cast<unsigned char>(a[i]);
      const auto cb = static_cast<unsigned char>(b[j]);
      if (ca != cb) return ca < cb;
      ++i;
      ++j;
    }
  }
  const bool a_done = i == a.size();
  const bool b_done = j == b.size();
  if (a_done != b_done) return a_done;
  return a < b;
}

const std::vector<std::string>& SupportedImageExtensions() {
  static const std::vector<std::string> kExtensions = {"png", "jpg", "jpeg", "tif", "tiff",
                                                       "pgm", "ppm", "pnm",  "pbm", "bmp"};
  return kExtensions;
}

std::vector<std::string> ListImages(const std::string& folder, const std::string& extension) {
  std::error_code ec;
  const fs::file_status status = fs::status(folder, ec);
  if (!fs::exists(status)) {
    throw InputError("folder " + Quoted(folder) + " does not exist" +
                     WorkingDirectoryNote(folder) + " (" + kExpectedFolder + ")");
  }
  if (!fs::is_directory(status)) {
    throw InputError("folder " + Quoted(folder) + " is not a folder but a file (" +
                     kExpectedFolder + ")");
  }

  const std::string wanted = NormalizeExtension(extension);
  const std::vector<std::string>& supported = SupportedImageExtensions();
  auto accepted = [&](const std::string& ext) {
    if (!wanted.empty()) return ext == wanted;
    return std::find(supported.begin(), supported.end(), ext) != supported.end();
  };

  std::vector<std::string> names;
  std::set<std::string> other_extensions;
  int file_count = 0;
  fs::directory_iterator it(folder, ec);
  const fs::directory_iterator end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name.front() == '.') continue;
    std::error_code file_ec;
    const std::string ext = ExtensionOf(name);
    // A symbolic link that leads nowhere (dangling, or a loop), or a FIFO, socket or device (or
    // a link to one, such as /dev/zero) under an image name is a frame the user meant: it is
    // listed so that reading it names it (or Skip_unreadable skips and counts it) instead of the
    // later frame numbers silently shifting. Folders are passed over.
    const bool broken_link = it->is_symlink(file_ec) && !fs::exists(it->path(), file_ec);
    std::error_code type_ec;
    const bool regular = it->is_regular_file(type_ec) && !type_ec;  // follows links
    const bool special = !broken_link && !regular && !type_ec &&
                         !it->is_directory(type_ec) && !type_ec;
    if (!broken_link && !regular && !special) continue;
    if ((broken_link || special) && !accepted(ext)) continue;
    ++file_count;
    if (accepted(ext)) {
      names.push_back(name);
    } else {
      other_extensions.insert(ext.empty() ? "(none)" : ext);
    }
  }
  if (ec) {
    throw InputError("folder " + Quoted(folder) + " cannot be listed: " + FirstLine(ec.message()) +
                     " (expected a readable folder of images)");
  }
  if (names.empty()) {
    std::string held =
        "it holds " + std::to_string(file_count) + (file_count == 1 ? " file" : " files");
    if (!other_extensions.empty()) {
      held += " with extension" + std::string(other_extensions.size() == 1 ? " " : "s ");
      int listed = 0;
      for (const std::string& e : other_extensions) {
        if (listed == 8) {
          held += ", ...";
          break;
        }
        held += (listed++ == 0 ? "" : ", ") + e;
      }
    }
    throw InputError("folder " + Quoted(folder) + " holds no image" +
                     (wanted.empty() ? std::string() : " with extension " + wanted) + " (" + held +
                     "; supported: " + JoinSupported() + ")");
  }

  std::sort(names.begin(), names.end(), NaturalLess);
  std::vector<std::string> paths;
  paths.reserve(names.size());
  for (const std::string& name : names) paths.push_back((fs::path(folder) / name).string());
  return paths;
}

cv::Mat ReadImageFile(const std::string& path) {
  auto fail = [&](const std::string& what) -> InputError {
    return InputError("image " + Quoted(path) + " " + what + " (" + kExpectedImage + ")");
  };

  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) {
    std::error_code link_ec;
    if (fs::is_symlink(fs::symlink_status(path, link_ec))) {
      const std::string target = fs::read_symlink(path, link_ec).string();
      throw fail("is a symbolic link to " + Quoted(target) + " that leads nowhere (" +
                 (ec ? FirstLine(ec.message()) : std::string("dangling: no such file")) + ")");
    }
    throw fail("does not exist" + WorkingDirectoryNote(path));
  }
  if (!fs::is_regular_file(status)) {
    const fs::file_type type = status.type();
    throw fail(std::string("is ") +
               (type == fs::file_type::fifo        ? "a FIFO (named pipe)"
                : type == fs::file_type::socket    ? "a socket"
                : type == fs::file_type::character ? "a character device"
                : type == fs::file_type::block     ? "a block device"
                : type == fs::file_type::directory ? "a folder"
                                                   : "a special file") +
               ", not a regular file");
  }
  if (fs::file_size(path, ec) == 0 && !ec) throw fail("is an empty file (0 bytes)");

  std::vector<unsigned char> bytes;
  {
    std::ifstream f(path, std::ios::binary);
    if (f) {
      f.seekg(0, std::ios::end);
      const std::streamoff size = f.tellg();
      if (size > 0) {
        bytes.resize(static_cast<std::size_t>(size));
        f.seekg(0);
        f.read(reinterpret_cast<char*>(bytes.data()), size);
      }
    }
    if (!f) throw fail("cannot be read (permission denied or I/O error)");
  }
  return DecodeBytes(bytes, path, [&] {
    cv::Mat frame;
    reinterpret_cast<OpenableOiioRead>(ModuleSymbol("oiio", "openable_oiio_read"))(path, frame);
    return frame;
  });
}

cv::Mat DecodeImageBytes(const std::string& bytes, const std::string& name) {
  if (bytes.empty()) {
    throw InputError("image " + Quoted(name) + " is empty (0 bytes) (" + kExpectedImage + ")");
  }
  const std::vector<unsigned char> data(bytes.begin(), bytes.end());
  return DecodeBytes(data, name, [&] {
    cv::Mat frame;
    reinterpret_cast<OpenableOiioReadMemory>(
        ModuleSymbol("oiio", "openable_oiio_read_memory"))(bytes, name, frame);
    return frame;
  });
}

std::unique_ptr<FrameSource> OpenImageFolder(const std::string& folder,
                                             const std::string& extension, int first, int last) {
  std::vector<std::string> paths = ListImages(folder, extension);
  const int count = static_cast<int>(paths.size());
  const int end =
      ResolveRangeEnd(first, last, count, "images", "image", "folder " + Quoted(folder));
  paths.erase(paths.begin() + end, paths.end());
  paths.erase(paths.begin(), paths.begin() + first);
  return std::make_unique<ImageFolderSource>(std::move(paths));
}

std::unique_ptr<FrameSource> OpenVideo(const std::string& path, int first, int last) {
  std::error_code ec;
  if (!fs::exists(path, ec) && path.find("://") == std::string::npos) {
    throw InputError("video " + Quoted(path) + " does not exist" + WorkingDirectoryNote(path) +
                     " (" + kExpectedVideo + ")");
  }
  // FFmpeg's "tty" demuxer renders any text file as ANSI-art frames, so a configuration or
  // ground-truth file given as a video by mistake would "work". Refuse the usual text types.
  static const std::set<std::string> kTextExtensions = {"txt", "csv", "yaml", "yml", "json",
                                                        "md", "xml"};
  if (kTextExtensions.count(ExtensionOf(path)) != 0) {
    throw InputError("video " + Quoted(path) + " is a text file (." + ExtensionOf(path) + "); " +
                     kExpectedVideo);
  }
  std::unique_ptr<FrameSource> source;
  reinterpret_cast<OpenableVideoOpen>(ModuleSymbol("video", "openable_video_open"))(path, first,
                                                                                    last, source);
  return source;
}

std::unique_ptr<FrameSource> OpenBag(const std::string& path, const std::string& topic,
                                     int first, int last, const std::string& key,
                                     const std::string& topic_key) {
  if (path.empty())
    throw InputError(key + ": empty; expected the path of a ROS 1 bag (Frame_mode 3)");
  if (topic.empty())
    throw InputError(topic_key + ": empty; expected the image topic of bag " + Quoted(path) +
                     " to read (e.g. /cam0/image_raw)");
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(key + ": bag " + Quoted(path) + " does not exist" +
                     WorkingDirectoryNote(path) + " (expected a ROS 1 bag)");
  std::unique_ptr<FrameSource> source;
  reinterpret_cast<OpenableRosbagOpen>(ModuleSymbol("rosbag", "openable_rosbag_open"))(
      path, topic, first, last, key, topic_key, source);
  return source;
}

}  // namespace openable
