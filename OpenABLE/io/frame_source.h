// Frame sources: where the frames of a run come from (a folder of images or a video).
//
// A frame is returned as the image was stored, converted to floating point: CV_32FC1 (grey) or
// CV_32FC3 (colour, BGR order as everywhere in OpenCV), values in [0, 1] whatever the bit depth
// of the file (8- or 16-bit). Preprocessing (grey conversion, illumination invariance) happens
// later, in OpenABLE/image/preprocess.h.
#pragma once

#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace openable {

// "Natural" order of file names: runs of digits compare by their numeric value, so "img2"
// comes before "img10"; the rest compares character by character. Ties (e.g. "a01" and "a1")
// are broken by plain lexicographic order so that the order is total.
bool NaturalLess(const std::string& a, const std::string& b);

// File name extensions (lower case, no dot) that ListImages accepts when no format is given.
const std::vector<std::string>& SupportedImageExtensions();

// Lists the image files of `folder` in natural order of their file names (not recursive).
// `extension` (e.g. "png", case-insensitive, with or without a dot) keeps only those files;
// empty keeps every supported image extension. Subfolders are passed over; a symbolic link
// that leads nowhere (dangling or a loop) under an image name is listed, so that reading it
// names it. Throws InputError when the folder is missing, is not a folder, or holds no
// matching image.
std::vector<std::string> ListImages(const std::string& folder, const std::string& extension);

// Reads one image file through OpenImageIO (PNG, JPEG, TIFF, PGM/PPM, BMP, ...; 8 or 16 bit;
// 1, 2, 3 or 4 channels; alpha is dropped, grey+alpha becomes grey). Returns CV_32FC1 or
// CV_32FC3 (BGR) in [0, 1]. Throws InputError naming the file when it cannot be opened or
// decoded (missing, a broken symbolic link, corrupt, truncated, a JPEG libjpeg warns about,
// not an image) or is a PNG or JPEG of more than 100 megapixels (docs/robustness.md).
cv::Mat ReadImageFile(const std::string& path);

// Decodes the bytes of an image file held in memory exactly as ReadImageFile decodes a file
// (OpenCV's codecs first, OpenImageIO from memory for the rest); `name` names the image in
// messages. Throws InputError when the bytes are not a readable image. Used by the image
// fuzzer (tests/fuzz/image_fuzzer.cc).
cv::Mat DecodeImageBytes(const std::string& bytes, const std::string& name);

// A sequence of frames with random access by index.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Number of frames.
  virtual int Size() const = 0;
  // Human-readable name of frame i: the file path, or "<video>#<frame index>".
  virtual std::string FrameName(int i) const = 0;
  // Reads frame i (see the top of this file for the format). Throws InputError naming the
  // frame when it cannot be read. Thread-safe when ParallelReads() is true.
  virtual cv::Mat Read(int i) const = 0;
  // True when Read may be called from several threads at once (image folders); false for
  // videos, which must be read in order from one thread.
  virtual bool ParallelReads() const = 0;
  // The time frame i was taken, in seconds, when the source records it (a ROS bag: the
  // message's header stamp), else NaN. Thread-safe. (Defined here: FrameSource has no key
  // function, so the modules deriving from it, which do not link openable_io, get its type
  // information inline.)
  virtual double Timestamp(int /*i*/) const { return std::numeric_limits<double>::quiet_NaN(); }
};

// The images of `folder` (see ListImages), restricted to the positions [first, last) of the
// natural order. last = -1 means "to the end". Throws InputError when the range is empty or
// outside the folder's images (the message names the folder, the count and the keys
// Initial_image / Final_image).
std::unique_ptr<FrameSource> OpenImageFolder(const std::string& folder,
                                             const std::string& extension, int first, int last);

// The frames [first, last) of a video file opened with OpenCV's VideoCapture; last = -1 means
// "to the end". Opening counts the frames by grabbing them once (a container's frame count is
// not reliable); Read(i) is cheapest in increasing order of i (a step back reopens the file).
// Not thread-safe: ParallelReads() is false. Throws InputError when the file cannot be opened,
// holds no frame, or the range is outside it.
std::unique_ptr<FrameSource> OpenVideo(const std::string& path, int first, int last);

// The messages [first, last) of `topic` in the ROS 1 bag `path` (rosbag record: EuRoC, TUM-VI
// and most recorded robot data), in the order of the bag (record time), read with Debian's
// rosbag_storage in the module libopenable_rosbag.so. Topics of type sensor_msgs/Image
// (encodings mono8, mono16, 8UC1, 16UC1, bgr8, rgb8, bgra8, rgba8, 8UC3, 8UC4) and
// sensor_msgs/CompressedImage (JPEG or PNG). Frames are returned as every source returns them
// (RGB reordered to BGR, alpha dropped, 16-bit scaled by 1/65535); Timestamp(i) is the
// message's header stamp (its record time when the stamp is zero); FrameName(i) is
// "<bag file name>:<topic>#<message index>". `key` and `topic_key` name the Config.txt keys in
// messages (Bag_path, Bag_topic, ...). Throws InputError with one line naming the bag, the
// topic and what was expected: a missing or unreadable file, a file that is not a bag or is
// truncated (no index), a topic that is absent (the bag's image topics are listed) or of
// another type, an empty range; Read(i) when a message cannot be decoded. Reads are
// thread-safe: the bag is read under a lock, messages are decoded outside it.
std::unique_ptr<FrameSource> OpenBag(const std::string& path, const std::string& topic, int first,
                                     int last, const std::string& key,
                                     const std::string& topic_key);

}  // namespace openable
