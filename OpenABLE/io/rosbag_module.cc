// libopenable_rosbag.so: image topics of ROS 1 bags as frame sources (OpenBag,
// frame_source.h), read with Debian's rosbag_storage (librosbag-storage-dev) and the message
// types of libsensor-msgs-dev. A module: rosbag_storage pulls in Boost, console_bridge, lz4,
// bz2 and the ROS plugin loader, which a run without bags does not load.
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/module_api.h"
#include "OpenABLE/io/rosbag_check.h"

namespace openable {
namespace {

constexpr const char* kImage = "sensor_msgs/Image";
constexpr const char* kCompressed = "sensor_msgs/CompressedImage";

// The frame of a sensor_msgs/Image (frame_source.h's format), or an InputError naming it.
cv::Mat DecodeImage(const sensor_msgs::Image& m, const std::string& what) {
  struct Layout {
    int type;     // of the message's pixels
    int convert;  // cv::cvtColor code to BGR or grey, -1: none
  };
  static const std::map<std::string, Layout> kEncodings = {
      {"mono8", {CV_8UC1, -1}},
      {"8UC1", {CV_8UC1, -1}},
      {"mono16", {CV_16UC1, -1}},
      {"16UC1", {CV_16UC1, -1}},
      {"bgr8", {CV_8UC3, -1}},
      {"8UC3", {CV_8UC3, -1}},
      {"rgb8", {CV_8UC3, cv::COLOR_RGB2BGR}},
      {"bgra8", {CV_8UC4, cv::COLOR_BGRA2BGR}},
      {"8UC4", {CV_8UC4, cv::COLOR_BGRA2BGR}},
      {"rgba8", {CV_8UC4, cv::COLOR_RGBA2BGR}},
      {"bgr16", {CV_16UC3, -1}},
      {"rgb16", {CV_16UC3, cv::COLOR_RGB2BGR}},
  };
  const auto found = kEncodings.find(m.encoding);
  if (found == kEncodings.end()) {
    std::string known;
    for (const auto& [name, layout] : kEncodings) known += (known.empty() ? "" : ", ") + name;
    throw InputError(what + ": encoding " + Quoted(m.encoding) + "; expected one of " + known);
  }
  const Layout layout = found->second;
  const std::size_t pixel = CV_ELEM_SIZE(layout.type);
  // Each condition on its own, so that the message states the one that failed.
  const std::string size = std::to_string(m.width) + " x " + std::to_string(m.height);
  if (m.width == 0 || m.height == 0)
    throw InputError(what + ": the image is " + size +
                     " pixels (width x height); expected at "
                     "least 1 x 1");
  if (m.width > 100000 || m.height > 100000)
    throw InputError(what + ": the image is " + size +
                     " pixels (width x height); expected at "
                     "most 100000 on each side");
  const std::uint64_t row_bytes = static_cast<std::uint64_t>(m.width) * pixel;
  if (m.step < row_bytes)
    throw InputError(what + ": step " + std::to_string(m.step) +
                     " bytes is shorter than a row of " + size + " " + m.encoding + " (" +
                     std::to_string(row_bytes) + " bytes); expected step >= width x " +
                     std::to_string(pixel) + " bytes");
  const std::uint64_t needed = static_cast<std::uint64_t>(m.step) * m.height;
  if (needed > m.data.size())
    throw InputError(what + ": " + std::to_string(m.data.size()) + " bytes of data for " + size +
                     " " + m.encoding + " rows of step " + std::to_string(m.step) +
                     "; expected height x step = " + std::to_string(needed) + " bytes");
  cv::Mat pixels(static_cast<int>(m.height), static_cast<int>(m.width), layout.type,
                 const_cast<unsigned char*>(m.data.data()), m.step);
  pixels = pixels.clone();
  // 16-bit data in the other byte order than this machine's.
  constexpr bool kLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;
  if (pixels.depth() == CV_16U && (m.is_bigendian != 0) == kLittleEndian) {
    for (int r = 0; r < pixels.rows; ++r) {
      auto* p = pixels.ptr<std::uint16_t>(r);
      for (int c = 0; c < pixels.cols * pixels.channels(); ++c)
        p[c] = static_cast<std::uint16_t>((p[c] >> 8) | (p[c] << 8));
    }
  }
  if (layout.convert >= 0) cv::cvtColor(pixels, pixels, layout.convert);
  cv::Mat frame;
  pixels.convertTo(frame, CV_32F, pixels.depth() == CV_16U ? 1.0 / 65535.0 : 1.0 / 255.0);
  return frame;
}

// rosbag_storage reads a damaged bag unsafely: its structure is checked first (before a
// rosbag::Bag is made, whose encryptor plug-in is looked up through ROS's package index).
void CheckBag(const std::string& path, const std::string& key) {
  const std::string defect = BagDefect(path);
  if (!defect.empty())
    throw InputError(key + ": bag " + Quoted(path) + " cannot be read (" + defect +
                     "); expected a complete ROS 1 bag of format 2.0 (rosbag record)");
}

class BagSource final : public FrameSource {
 public:
  BagSource(const std::string& path, const std::string& topic, int first, int last,
            const std::string& key, const std::string& topic_key)
      : path_(path), topic_(topic), name_(std::filesystem::path(path).filename().string()) {
    const std::string bag_text = "bag " + Quoted(path);
    try {
      bag_.open(path, rosbag::bagmode::Read);
    } catch (const rosbag::BagException& e) {
      throw InputError(key + ": " + bag_text + " cannot be read (" + Escaped(e.what()) +
                       "); expected a complete ROS 1 bag (rosbag record; a recording cut short "
                       "has no index: rosbag reindex repairs it)");
    }
    // Every topic of the bag, with its type: to name them when the topic asked for is not there.
    std::map<std::string, std::string> topics;
    std::map<std::string, std::set<std::string>> types_of_topic;  // a topic may mix types
    {
      rosbag::View all(bag_);
      for (const rosbag::ConnectionInfo* c : all.getConnections()) {
        topics[c->topic] = c->datatype;
        types_of_topic[c->topic].insert(c->datatype);
      }
    }
    const auto type = topics.find(topic);
    if (type == topics.end()) {
      std::string images, others;
      for (const auto& [t, datatype] : topics) {
        std::string& list = datatype == kImage || datatype == kCompressed ? images : others;
        list += (list.empty() ? "" : ", ") + Escaped(t) + " (" + Escaped(datatype) + ")";
      }
      throw InputError(
          topic_key + ": topic " + Quoted(topic) + " is not in " + bag_text +
          "; expected an image topic of the bag: " + (images.empty() ? "it has none" : images) +
          (others.empty() ? "" : "; other topics: " + others));
    }
    if (const std::set<std::string>& types = types_of_topic[topic]; types.size() > 1) {
      std::string list;
      for (const std::string& t : types) list += (list.empty() ? "" : ", ") + Escaped(t);
      throw InputError(topic_key + ": topic " + Quoted(topic) + " of " + bag_text + " carries " +
                       std::to_string(types.size()) + " message types (" + list +
                       "); expected one: " + kImage + " or " + kCompressed);
    }
    if (type->second != kImage && type->second != kCompressed)
      throw InputError(topic_key + ": topic " + Quoted(topic) + " of " + bag_text + " holds " +
                       Escaped(type->second) + "; expected " + kImage + " or " + kCompressed);
    compressed_ = type->second == kCompressed;
    try {
      rosbag::View view(bag_, rosbag::TopicQuery(std::vector<std::string>{topic}));
      for (const rosbag::MessageInstance& m : view) messages_.push_back(m);
    } catch (const rosbag::BagException& e) {
      throw InputError(key + ": " + bag_text + " cannot be read (" + Escaped(e.what()) +
                       "); expected a complete ROS 1 bag");
    }
    const int count = static_cast<int>(messages_.size());
    if (count == 0)
      throw InputError(topic_key + ": topic " + Quoted(topic) + " of " + bag_text +
                       " holds no message; expected at least one " + Escaped(type->second) +
                       " message");
    const int end = last < 0 ? count : std::min(last, count);
    if (count == 0 || first >= end)
      throw InputError(topic_key + ": topic " + Quoted(topic) + " of " + bag_text + " holds " +
                       std::to_string(count) + " messages; the range Initial_image " +
                       std::to_string(first) + " to Final_image " + std::to_string(last) +
                       " keeps none (expected at least one image message in the range)");
    messages_ =
        std::vector<rosbag::MessageInstance>(messages_.begin() + first, messages_.begin() + end);
    first_ = first;
    stamps_.assign(messages_.size(), std::numeric_limits<double>::quiet_NaN());
  }

  int Size() const override { return static_cast<int>(messages_.size()); }
  // The bag is read under a lock (rosbag::Bag is not thread-safe); messages are decoded
  // outside it, so a run decodes compressed frames on every core.
  bool ParallelReads() const override { return true; }

  std::string FrameName(int i) const override {
    return name_ + ":" + topic_ + "#" + std::to_string(first_ + i);
  }

  cv::Mat Read(int i) const override {
    const std::string what = "bag " + Quoted(path_) + ", topic " + Quoted(topic_) + ", message " +
                             std::to_string(first_ + i);
    Message message = Load(i, what);
    try {
      if (compressed_) {
        const sensor_msgs::CompressedImage& m = *message.compressed;
        const std::string bytes(m.data.begin(), m.data.end());
        return DecodeImageBytes(bytes, what + " (" + Escaped(m.format) + ")");
      }
      return DecodeImage(*message.image, what);
    } catch (const ros::Exception& e) {
      throw InputError(what + " cannot be decoded (" + Escaped(e.what()) + ")");
    }
  }

  double Timestamp(int i) const override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!std::isnan(stamps_.at(i))) return stamps_[i];
    }
    Load(i, "bag " + Quoted(path_) + ", topic " + Quoted(topic_) + ", message " +
                std::to_string(first_ + i));
    std::lock_guard<std::mutex> lock(mutex_);
    return stamps_[i];
  }

 private:
  struct Message {
    boost::shared_ptr<sensor_msgs::Image> image;
    boost::shared_ptr<sensor_msgs::CompressedImage> compressed;
  };

  // Reads and deserialises message i (under the lock) and records its stamp.
  Message Load(int i, const std::string& what) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const rosbag::MessageInstance& m = messages_.at(i);
    Message out;
    ros::Time stamp;
    try {
      if (compressed_) {
        out.compressed = m.instantiate<sensor_msgs::CompressedImage>();
        if (!out.compressed) throw InputError(what + ": not a " + std::string(kCompressed));
        stamp = out.compressed->header.stamp;
      } else {
        out.image = m.instantiate<sensor_msgs::Image>();
        if (!out.image) throw InputError(what + ": not a " + std::string(kImage));
        stamp = out.image->header.stamp;
      }
    } catch (const rosbag::BagException& e) {
      throw InputError(what + " cannot be read (" + Escaped(e.what()) +
                       "); expected a complete message (a damaged or truncated bag?)");
    } catch (const ros::Exception& e) {
      // The bytes do not fit the type the topic's connection declares. A bag cannot tell which
      // of two causes it is: a message of another type written under that connection (rosbag's
      // writer files a topic's messages under its first connection unless each comes with its
      // own connection header), or damage.
      const std::string type = compressed_ ? kCompressed : kImage;
      throw InputError(what + " does not decode as " + type + ", the type its connection " +
                       "declares (" + Escaped(e.what()) + "); expected " + type +
                       " messages only: a " +
                       "message of another type written on the topic, or a damaged bag");
    }
    if (stamp.isZero()) stamp = m.getTime();  // no header stamp: the record time
    stamps_[i] = stamp.toSec();
    return out;
  }

  std::string path_, topic_, name_;
  rosbag::Bag bag_;
  std::vector<rosbag::MessageInstance> messages_;
  bool compressed_ = false;
  int first_ = 0;
  mutable std::mutex mutex_;  // rosbag::Bag reads are not thread-safe; guards stamps_ too
  mutable std::vector<double> stamps_;
};

}  // namespace
}  // namespace openable

extern "C" void openable_rosbag_open(const std::string& path, const std::string& topic, int first,
                                     int last, const std::string& key, const std::string& topic_key,
                                     std::unique_ptr<openable::FrameSource>& source) {
  openable::CheckBag(path, key);
  source = std::make_unique<openable::BagSource>(path, topic, first, last, key, topic_key);
}
