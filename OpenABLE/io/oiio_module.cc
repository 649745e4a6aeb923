// Module libopenable_oiio.so (see module_loader.h): image decoding through OpenImageIO, for
// TIFF and for the files OpenCV's decoders refuse (so that the error names the real problem).
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/typedesc.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/io_common.h"
#include "OpenABLE/io/module_api.h"

using namespace openable;
using namespace openable::io_internal;

namespace {

// Opens `file` with the reader its extension names or else with the first still-image reader
// that recognises it; an empty pointer and `error` set when none does. ImageInput::open would
// do the same but also offer the file to the FFmpeg (video) reader, which a damaged image can
// drive into an exception or a leak (found by the image fuzzer); frames here are still images,
// and videos go through OpenCV's videoio instead.
// The OpenImageIO format whose readers claim the extension of `file` ("tif" -> "tiff"), from
// its "extension_list" attribute ("tiff:tif,tiff;jpeg:jpg,jpe,jpeg;..."); empty when none
// does. ImageInput::create given a file name instead would, for an unknown extension, open
// the file with every reader, FFmpeg's included, which leaks its codec context on bytes that
// are not a video (found by the image fuzzer: 944 bytes from avcodec_alloc_context3).
std::string FormatOfExtension(const std::string& file) {
  std::string extension = std::filesystem::path(file).extension().string();
  if (extension.size() < 2) return "";
  extension = extension.substr(1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::string list = OIIO::get_string_attribute("extension_list");
  std::size_t begin = 0;
  while (begin < list.size()) {
    const std::size_t end = std::min(list.find(';', begin), list.size());
    const std::string entry = list.substr(begin, end - begin);
    const std::size_t colon = entry.find(':');
    if (colon != std::string::npos) {
      const std::string extensions = "," + entry.substr(colon + 1) + ",";
      if (extensions.find("," + extension + ",") != std::string::npos)
        return entry.substr(0, colon);
    }
    begin = end + 1;
  }
  return "";
}

std::unique_ptr<OIIO::ImageInput> OpenImageReader(const std::string& file,
                                                  const OIIO::ImageSpec& config,
                                                  std::string& error) {
  error.clear();
  auto try_reader = [&](const std::string& format) -> std::unique_ptr<OIIO::ImageInput> {
    if (format.empty() || format == "ffmpeg") return nullptr;
    auto in = OIIO::ImageInput::create(format, /*do_open=*/false, &config);
    if (!in || std::string(in->format_name()) == "ffmpeg" || !in->valid_file(file)) {
      (void)OIIO::geterror();  // the complaint of a reader the file is not for
      return nullptr;
    }
    OIIO::ImageSpec spec;
    if (in->open(file, spec, config)) return in;
    if (error.empty()) error = in->geterror();  // the file's own reader, failing on it
    return nullptr;
  };
  // The reader of the extension, if there is one.
  if (auto in = try_reader(FormatOfExtension(file))) return in;
  const std::string formats = OIIO::get_string_attribute("input_format_list");
  for (std::size_t begin = 0; begin < formats.size();) {
    const std::size_t end = std::min(formats.find(',', begin), formats.size());
    if (auto in = try_reader(formats.substr(begin, end - begin))) return in;
    begin = end + 1;
  }
  if (error.empty()) error = "no image reader of OpenImageIO recognises its contents";
  return nullptr;
}

// Decodes the file `oiio_name`, named `path` in messages.
void ReadUnguarded(const std::string& path, const std::string& oiio_name, cv::Mat& frame) {
  auto fail = [&](const std::string& what) -> InputError {
    return InputError("image " + Quoted(path) + " " + what + " (" + kExpectedImage + ")");
  };
  // Keep the colour values as stored when there is an alpha channel (OIIO would otherwise
  // premultiply them by alpha), since the alpha channel is dropped below.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  std::string error;
  auto in = OpenImageReader(oiio_name, config, error);
  if (!in) throw fail("cannot be decoded: " + FirstLine(error));
  // Callers read many files in parallel; one thread per file avoids OIIO's own fan-out.
  in->threads(1);

  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.depth <= 0) {
    throw fail("is empty (" + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
               " pixels)");
  }
  if (spec.depth != 1) {
    throw fail("is a volume of " + std::to_string(spec.depth) + " slices, not a 2D image");
  }
  int channels = 0;  // channels kept: grey, or the three colour channels
  switch (spec.nchannels) {
    case 1:
    case 2:
      channels = 1;
      break;
    case 3:
    case 4:
      channels = 3;
      break;
    default:
      throw fail("has " + std::to_string(spec.nchannels) + " channels (1 to 4 are supported)");
  }

  // 8- and 16-bit files are read as stored and converted to float by OpenCV afterwards:
  // OpenImageIO's own conversion to float costs more than decoding (docs/benchmarks.md,
  // "End-to-end run times and start-up").
  const OIIO::TypeDesc::BASETYPE base = static_cast<OIIO::TypeDesc::BASETYPE>(spec.format.basetype);
  const bool uniform = spec.channelformats.empty();
  int stored_depth = CV_32F;
  OIIO::TypeDesc read_as = OIIO::TypeDesc::FLOAT;
  double scale = 1.0;
  if (uniform && base == OIIO::TypeDesc::UINT8) {
    stored_depth = CV_8U;
    read_as = OIIO::TypeDesc::UINT8;
    scale = 1.0 / 255.0;
  } else if (uniform && base == OIIO::TypeDesc::UINT16) {
    stored_depth = CV_16U;
    read_as = OIIO::TypeDesc::UINT16;
    scale = 1.0 / 65535.0;
  }
  // A corrupt header can announce terabytes (the image fuzzer found a 5.4e11-pixel PGM header),
  // so the size is checked before allocating, with the limit OpenCV's own decoders use:
  // OPENCV_IO_MAX_IMAGE_PIXELS, 2^30 pixels by default.
  std::int64_t max_pixels = std::int64_t{1} << 30;
  if (const char* env = std::getenv("OPENCV_IO_MAX_IMAGE_PIXELS"); env != nullptr && *env != '\0') {
    max_pixels = std::max<std::int64_t>(1, std::atoll(env));
  }
  if (std::int64_t{spec.width} * spec.height > max_pixels) {
    throw fail("is too large to read: its header announces " + std::to_string(spec.width) + " x " +
               std::to_string(spec.height) + " pixels, more than " + std::to_string(max_pixels) +
               " (OPENCV_IO_MAX_IMAGE_PIXELS)");
  }
  cv::Mat image;
  try {
    image.create(spec.height, spec.width, CV_MAKETYPE(stored_depth, channels));
  } catch (const std::exception&) {  // cv::Exception or std::bad_alloc: a corrupt header?
    throw fail("is too large to read: " + std::to_string(spec.width) + " x " +
               std::to_string(spec.height) + " pixels x " + std::to_string(channels) +
               " channels do not fit in memory");
  }
  const bool read = in->read_image(/*subimage=*/0, /*miplevel=*/0, /*chbegin=*/0,
                                   /*chend=*/channels, read_as, image.data);
  // Some readers (JPEG) fill a truncated file with grey and succeed with an error recorded.
  if (!read || in->has_error()) {
    std::string reason = in->geterror();
    if (reason.empty()) reason = OIIO::geterror();
    throw fail("cannot be decoded: " + FirstLine(reason));
  }
  if (!in->close() || in->has_error()) {
    throw fail("cannot be decoded: " + FirstLine(in->geterror()));
  }
  if (stored_depth != CV_32F) image.convertTo(image, CV_MAKETYPE(CV_32F, channels), scale);

  if (channels == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  const bool unsigned_integer = base == OIIO::TypeDesc::UINT8 || base == OIIO::TypeDesc::UINT16 ||
                                base == OIIO::TypeDesc::UINT32 || base == OIIO::TypeDesc::UINT64;
  if (!unsigned_integer || !spec.channelformats.empty()) {
    // Float or signed pixels may leave [0, 1] (or be NaN); bring them back into it.
    cv::patchNaNs(image, 0.0);
    cv::min(image, 1.0, image);
    cv::max(image, 0.0, image);
  }
  frame = image;
}

// ReadUnguarded, with any other exception from inside OpenImageIO named as a decoding failure
// of the file. A damaged file that no reader claims is offered to every reader OpenImageIO
// has, its FFmpeg (video) reader included, and that reader has thrown std::length_error on
// bytes the image fuzzer made; such an exception must not end the program.
void Read(const std::string& path, const std::string& oiio_name, cv::Mat& frame) {
  try {
    ReadUnguarded(path, oiio_name, frame);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("image " + Quoted(path) + " cannot be decoded: OpenImageIO failed (" +
                     FirstLine(e.what()) + ") (" + kExpectedImage + ")");
  }
}

}  // namespace

extern "C" void openable_oiio_read(const std::string& path, cv::Mat& frame) {
  Read(path, path, frame);
}

extern "C" void openable_oiio_read_memory(const std::string& bytes, const std::string& name,
                                          cv::Mat& frame) {
  // OpenImageIO 2.4's readers do not all read from memory (an IOMemReader proxy: its TIFF
  // reader still opens the file by name), so the bytes go through a temporary file, whose
  // extension, told by the bytes' signature, is OpenImageIO's first guess of the format.
  auto starts = [&](const char* signature, std::size_t n) {
    return bytes.size() >= n && bytes.compare(0, n, signature, n) == 0;
  };
  std::string extension;
  if (starts("\x89PNG", 4)) {
    extension = "png";
  } else if (starts("\xFF\xD8\xFF", 3)) {
    extension = "jpg";
  } else if (starts("II*\0", 4) || starts("MM\0*", 4)) {
    extension = "tif";
  } else if (starts("BM", 2)) {
    extension = "bmp";
  } else if (bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6') {
    extension = "pnm";
  } else if (starts("GIF8", 4)) {
    extension = "gif";
  } else if (starts("RIFF", 4) && bytes.size() >= 12 && bytes.compare(8, 4, "WEBP") == 0) {
    extension = "webp";
  } else if (starts("v/1\x01", 4)) {
    extension = "exr";
  }
  extension = extension.empty() ? "" : "." + extension;
  const char* tmp = std::getenv("TMPDIR");
  std::string file = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") +
                     "/openable_image_XXXXXX" + extension;
  const int fd = mkstemps(file.data(), static_cast<int>(extension.size()));
  if (fd < 0) {
    throw InputError("image " + Quoted(name) + " cannot be decoded: no temporary file for " +
                     "OpenImageIO (" + FirstLine(std::strerror(errno)) + ")");
  }
  struct Remove {
    std::string path;
    ~Remove() { std::remove(path.c_str()); }
  } remove{file};
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = write(fd, bytes.data() + written, bytes.size() - written);
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  close(fd);
  if (written != bytes.size()) {
    throw InputError("image " + Quoted(name) + " cannot be decoded: the temporary file for " +
                     "OpenImageIO could not be written");
  }
  Read(name, file, frame);
}
