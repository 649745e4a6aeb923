// Module libopenable_video.so (see module_loader.h): video files through OpenCV's videoio.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/io_common.h"
#include "OpenABLE/io/module_api.h"

namespace openable {
namespace {

using namespace io_internal;

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
}  // namespace openable

extern "C" void openable_video_open(const std::string& path, int first, int last,
                                    std::unique_ptr<openable::FrameSource>& source) {
  using namespace openable;
  using namespace openable::io_internal;
  int count = 0;
  int api = -1;
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) == 0 &&
      !ec)
    throw InputError("video " + Quoted(path) + " is an empty file (0 bytes; " + kExpectedVideo +
                     ")");
  // FFmpeg logs its complaints about a damaged file ("moov atom not found") on stderr before
  // OpenCV reports failure; our message says it in one line, so FFmpeg is kept quiet (unless
  // the user asked for its log level).
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
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
  source = std::make_unique<VideoSource>(path, api, first, end - first, count);
}
