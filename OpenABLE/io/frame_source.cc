#include "OpenABLE/io/frame_source.h"

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/image_codec.h"
#include "OpenABLE/io/io_common.h"
#include "OpenABLE/io/module_api.h"

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
    throw InputError("folder " + Quoted(folder) + " does not exist" + WorkingDirectoryNote(folder) +
                     " (" + kExpectedFolder + ")");
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
    const bool special =
        !broken_link && !regular && !type_ec && !it->is_directory(type_ec) && !type_ec;
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
  const std::string data = ReadInputFile(path, "image " + Quoted(path), kExpectedImage);
  if (data.empty()) {
    throw InputError("image " + Quoted(path) + " is an empty file (0 bytes) (" + kExpectedImage +
                     ")");
  }
  const std::vector<unsigned char> bytes(data.begin(), data.end());
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
    reinterpret_cast<OpenableOiioReadMemory>(ModuleSymbol("oiio", "openable_oiio_read_memory"))(
        bytes, name, frame);
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
  // A URL ("rtsp://...") goes to OpenCV as it is; a path must be a regular file (a FIFO would
  // block FFmpeg's probe for ever).
  if (path.find("://") == std::string::npos)
    CheckInputFile(path, "video " + Quoted(path), kExpectedVideo);
  // FFmpeg's "tty" demuxer renders any text file as ANSI-art frames, so a configuration or
  // ground-truth file given as a video by mistake would "work". Refuse the usual text types.
  static const std::set<std::string> kTextExtensions = {"txt",  "csv", "yaml", "yml",
                                                        "json", "md",  "xml"};
  if (kTextExtensions.count(ExtensionOf(path)) != 0) {
    throw InputError("video " + Quoted(path) + " is a text file (." + ExtensionOf(path) + "); " +
                     kExpectedVideo);
  }
  std::unique_ptr<FrameSource> source;
  reinterpret_cast<OpenableVideoOpen>(ModuleSymbol("video", "openable_video_open"))(path, first,
                                                                                    last, source);
  return source;
}

std::unique_ptr<FrameSource> OpenBag(const std::string& path, const std::string& topic, int first,
                                     int last, const std::string& key,
                                     const std::string& topic_key) {
  if (path.empty())
    throw InputError(key + ": empty; expected the path of a ROS 1 bag (Frame_mode 3)");
  if (topic.empty())
    throw InputError(topic_key + ": empty; expected the image topic of bag " + Quoted(path) +
                     " to read (e.g. /cam0/image_raw)");
  CheckInputFile(path, key + ": bag " + Quoted(path), "expected a ROS 1 bag");
  std::unique_ptr<FrameSource> source;
  reinterpret_cast<OpenableRosbagOpen>(ModuleSymbol("rosbag", "openable_rosbag_open"))(
      path, topic, first, last, key, topic_key, source);
  return source;
}

}  // namespace openable
