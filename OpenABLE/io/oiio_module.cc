// Module libopenable_oiio.so (see module_loader.h): image decoding through OpenImageIO, for
// TIFF and for the files OpenCV's decoders refuse (so that the error names the real problem).
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/typedesc.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <opencv2/imgproc.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/io_common.h"
#include "OpenABLE/io/module_api.h"

using namespace openable;
using namespace openable::io_internal;

namespace {

// Decodes the file `oiio_name`, named `path` in messages.
void Read(const std::string& path, const std::string& oiio_name, cv::Mat& frame) {
  auto fail = [&](const std::string& what) -> InputError {
    return InputError("image " + Quoted(path) + " " + what + " (" + kExpectedImage + ")");
  };
  // Keep the colour values as stored when there is an alpha channel (OIIO would otherwise
  // premultiply them by alpha), since the alpha channel is dropped below.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(oiio_name, &config);
  if (!in) throw fail("cannot be decoded: " + FirstLine(OIIO::geterror()));
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
  // OpenImageIO's own conversion to float costs more than decoding (measured: 6.8 ms against
  // 2.3 ms for a 960x540 JPEG).
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
    throw fail("is too large to read: its header announces " + std::to_string(spec.width) +
               " x " + std::to_string(spec.height) + " pixels, more than " +
               std::to_string(max_pixels) + " (OPENCV_IO_MAX_IMAGE_PIXELS)");
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
