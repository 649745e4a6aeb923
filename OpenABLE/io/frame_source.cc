#include "OpenABLE/io/frame_source.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/typedesc.h>

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

constexpr const char* kExpectedFolder = "expected a folder of images";
constexpr const char* kExpectedImage = "expected a PNG/JPEG/TIFF/PGM/PPM/BMP image";
constexpr const char* kExpectedVideo = "expected a video file readable by FFmpeg/GStreamer";

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

std::string ToLower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}


// The first non-blank line of a library's error text, trimmed, without control characters.
std::string FirstLine(const std::string& text) {
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find_first_of("\r\n", begin);
    if (end == std::string::npos) end = text.size();
    std::string line;
    for (std::size_t k = begin; k < end; ++k) {
      const auto u = static_cast<unsigned char>(text[k]);
      line += (u < 0x20 || u == 0x7f) ? ' ' : text[k];
    }
    const std::size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos) {
      const std::size_t last = line.find_last_not_of(' ');
      return line.substr(first, last - first + 1);
    }
    begin = end + 1;
  }
  return "unknown error";
}

std::string JoinSupported() {
  std::string out;
  for (const std::string& e : SupportedImageExtensions()) out += (out.empty() ? "" : ", ") + e;
  return out;
}

// "png" for "png", ".png", ".PNG"; empty stays empty.
std::string NormalizeExtension(const std::string& extension) {
  std::string e = ToLower(extension);
  if (!e.empty() && e.front() == '.') e.erase(0, 1);
  return e;
}

// Lower-case extension of a file name, without the dot ("" when it has none).
std::string ExtensionOf(const std::string& file_name) {
  return NormalizeExtension(fs::path(file_name).extension().string());
}

// Resolves [first, last) (last = -1: to the end) against `count` items and returns the end;
// the error names the items (e.g. "images") and `where` they are (e.g. "folder \"/x\"").
int ResolveRangeEnd(int first, int last, int count, const std::string& what_plural,
                    const std::string& what_singular, const std::string& where) {
  const int end = last == -1 ? count : last;
  if (first < 0 || end > count || first >= end) {
    throw InputError("Initial_image/Final_image: range [" + std::to_string(first) + ", " +
                     (last == -1 ? std::string("end") : std::to_string(last)) +
                     ") is empty or outside the " + std::to_string(count) + " " +
                     (count == 1 ? what_singular : what_plural) + " of " + where);
  }
  return end;
}

// libpng prints "libpng error: ..." on stderr before OpenImageIO sees the error, and truncated
// files are the common corruption (an interrupted copy). So a file that starts as a PNG has its
// chunk layout walked first (headers only, no pixel data): returns why it is truncated, or ""
// when the chunks reach IEND within the file (or when it is not a PNG at all).
std::string PngTruncation(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  unsigned char header[8];
  if (!f.read(reinterpret_cast<char*>(header), 8) || !std::equal(header, header + 8, kSignature)) {
    return "";
  }
  f.seekg(0, std::ios::end);
  const auto size = static_cast<std::uint64_t>(f.tellg());
  std::uint64_t pos = 8;
  while (true) {
    if (pos + 8 > size) return "truncated PNG: the file ends before its IEND chunk";
    f.seekg(static_cast<std::streamoff>(pos));
    if (!f.read(reinterpret_cast<char*>(header), 8)) return "";  // let the decoder say why
    const std::uint64_t length = (std::uint64_t{header[0]} << 24) |
                                 (std::uint64_t{header[1]} << 16) |
                                 (std::uint64_t{header[2]} << 8) | std::uint64_t{header[3]};
    std::string type(reinterpret_cast<const char*>(header + 4), 4);
    const bool named = std::all_of(type.begin(), type.end(), [](char c) {
      return std::isalpha(static_cast<unsigned char>(c)) != 0;
    });
    if (!named) return "";  // corrupt rather than truncated: the decoder says why
    if (type == "IEND") return "";
    pos += 12 + length;  // length, type, data, CRC
    if (pos > size) return "truncated PNG: the file ends inside its " + type + " chunk";
  }
}

void CheckIndex(int i, int size, const char* where) {
  if (i < 0 || i >= size) {
    throw std::logic_error(std::string(where) + ": frame index " + std::to_string(i) +
                           " outside [0, " + std::to_string(size) + ")");
  }
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

// Converts a frame given by VideoCapture (8/16-bit, 1/3/4 channels, BGR) to the frame format.
cv::Mat VideoFrameToFloat(const cv::Mat& frame) {
  double scale = 1.0;
  switch (frame.depth()) {
    case CV_8U:
      scale = 1.0 / 255.0;
      break;
    case CV_16U:
      scale = 1.0 / 65535.0;
      break;
    default:
      return cv::Mat();
  }
  cv::Mat colour;
  switch (frame.channels()) {
    case 1:
    case 3:
      colour = frame;
      break;
    case 4:
      cv::cvtColor(frame, colour, cv::COLOR_BGRA2BGR);
      break;
    default:
      return cv::Mat();
  }
  cv::Mat out;
  colour.convertTo(out, CV_MAKETYPE(CV_32F, colour.channels()), scale);
  return out;
}

// Opens `path` with the first of OpenCV's file backends, in its order of priority (FFmpeg,
// GStreamer, ...), that accepts it; returns the backend, or -1. Left out: CAP_IMAGES (it reads
// numbered image sequences, not video files, and logs an error for any other name), and
// GStreamer whenever FFmpeg is present: FFmpeg reads every file GStreamer would, and GStreamer
// writes its own multi-line "GStreamer-CRITICAL" messages to stderr, outside OpenCV's logging,
// when it fails on a file, which would bury the one-line error.
int OpenCapture(cv::VideoCapture& capture, const std::string& path) {
  const std::vector<cv::VideoCaptureAPIs> apis = cv::videoio_registry::getStreamBackends();
  const bool has_ffmpeg = std::find(apis.begin(), apis.end(), cv::CAP_FFMPEG) != apis.end();
  for (const cv::VideoCaptureAPIs api : apis) {
    if (api == cv::CAP_IMAGES || (has_ffmpeg && api == cv::CAP_GSTREAMER)) continue;
    try {
      if (capture.open(path, api)) return api;
    } catch (const cv::Exception&) {
      // This backend cannot read the file; try the next one.
    }
    capture.release();
  }
  return -1;
}

// Frames [first, first + count) of a video. One capture is kept open with its position, so
// reading in increasing order decodes each frame once; a step back reopens the file.
class VideoSource final : public FrameSource {
 public:
  VideoSource(std::string path, int api, int first, int count, int total)
      : path_(std::move(path)), api_(api), first_(first), count_(count), total_(total) {}

  int Size() const override { return count_; }

  std::string FrameName(int i) const override {
    CheckIndex(i, Size(), "VideoSource::FrameName");
    return path_ + "#" + std::to_string(first_ + i);
  }

  cv::Mat Read(int i) const override {
    CheckIndex(i, Size(), "VideoSource::Read");
    // Not meant to be called from several threads (ParallelReads() is false); the lock only
    // keeps a misuse from corrupting the capture.
    std::lock_guard<std::mutex> lock(mutex_);
    const int target = first_ + i;
    try {
      if (!capture_.isOpened() || target < next_) {
        capture_.release();
        next_ = 0;
        if (!capture_.open(path_, api_)) {
          throw InputError("video " + Quoted(path_) +
                           " cannot be reopened by OpenCV to read frame " + std::to_string(target) +
                           " (" + kExpectedVideo + ")");
        }
      }
      while (next_ < target) {
        if (!capture_.grab()) throw InputError(FrameError(target, "the video ends before it"));
        ++next_;
      }
      cv::Mat frame;
      if (!capture_.read(frame) || frame.empty()) {
        throw InputError(FrameError(target, "it cannot be decoded"));
      }
      ++next_;
      cv::Mat out = VideoFrameToFloat(frame);
      if (out.empty()) {
        throw InputError(FrameError(target, "OpenCV gives it as an unsupported pixel type " +
                                                cv::typeToString(frame.type())));
      }
      return out;
    } catch (const cv::Exception& e) {
      capture_.release();
      throw InputError(FrameError(target, "OpenCV failed: " + FirstLine(e.what())));
    } catch (...) {
      capture_.release();
      throw;
    }
  }

  bool ParallelReads() const override { return false; }

 private:
  std::string FrameError(int frame, const std::string& reason) const {
    return "video " + Quoted(path_) + " frame " + std::to_string(frame) +
           " cannot be read: " + reason + " (expected one of the " + std::to_string(total_) +
           " frames counted when the video was opened)";
  }

  std::string path_;
  int api_;  // the OpenCV backend that read the video when it was opened
  int first_;
  int count_;
  int total_;  // frames in the file
  mutable std::mutex mutex_;
  mutable cv::VideoCapture capture_;
  mutable int next_ = 0;  // index in the file of the frame the next grab() returns
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
    throw InputError("folder " + Quoted(folder) + " does not exist (" + kExpectedFolder + ")");
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
    if (!it->is_regular_file(file_ec) || file_ec) continue;  // follows symlinks
    ++file_count;
    const std::string ext = ExtensionOf(name);
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
  if (!fs::exists(status)) throw fail("does not exist");
  if (!fs::is_regular_file(status)) throw fail("is not a regular file");
  if (fs::file_size(path, ec) == 0 && !ec) throw fail("is an empty file (0 bytes)");

  const std::string truncation = PngTruncation(path);
  if (!truncation.empty()) throw fail("cannot be decoded: " + truncation);

  // Keep the colour values as stored when there is an alpha channel (OIIO would otherwise
  // premultiply them by alpha), since the alpha channel is dropped below.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
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
  return image;
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
    throw InputError("video " + Quoted(path) + " does not exist (" + kExpectedVideo + ")");
  }
  // FFmpeg's "tty" demuxer renders any text file as ANSI-art frames, so a configuration or
  // ground-truth file given as a video by mistake would "work". Refuse the usual text types.
  static const std::set<std::string> kTextExtensions = {"txt", "csv", "yaml", "yml", "json",
                                                        "md", "xml"};
  if (kTextExtensions.count(ExtensionOf(path)) != 0) {
    throw InputError("video " + Quoted(path) + " is a text file (." + ExtensionOf(path) + "); " +
                     kExpectedVideo);
  }
  int count = 0;
  int api = -1;
  try {
    cv::VideoCapture capture;
    api = OpenCapture(capture, path);
    if (api < 0) {
      throw InputError("video " + Quoted(path) + " cannot be opened by OpenCV (" + kExpectedVideo +
                       ")");
    }
    // The container's frame count is not reliable: count the frames that can be grabbed.
    while (capture.grab()) ++count;
  } catch (const cv::Exception& e) {
    throw InputError("video " + Quoted(path) + " cannot be read by OpenCV: " + FirstLine(e.what()) +
                     " (" + kExpectedVideo + ")");
  }
  if (count == 0) {
    throw InputError("video " + Quoted(path) + " holds no frame that OpenCV can read (" +
                     kExpectedVideo + ")");
  }
  const int end = ResolveRangeEnd(first, last, count, "frames", "frame", "video " + Quoted(path));
  return std::make_unique<VideoSource>(path, api, first, end - first, count);
}

}  // namespace openable
