// Writes the seeds of the map and bag fuzzers that OpenABLE and rosbag_storage write
// themselves (tests/fuzz/corpus/map/, tests/fuzz/corpus/bag/): small saved maps of the
// detectors of tests/fuzz/map_detectors.h and small bags with the topic "/image".
//   build_fuzz/tests/fuzz/write_seeds tests/fuzz/corpus
// The other seeds are written by hand or by NumPy (docs/robustness.md, "Fuzz targets").
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "OpenABLE/io/image_codec.h"
#include "OpenABLE/online/online.h"
#include "tests/fuzz/map_detectors.h"

namespace {

using openable::OnlineDetector;
using openable::fuzz::MapDetectorOptions;
using openable::fuzz::MapFrame;
using openable::fuzz::MapKind;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// ---- Maps

void WriteMaps(const std::string& dir) {
  cv::RNG rng(7);
  {  // 40 LDB rows: 38 searchable, one index block of 32 rows.
    OnlineDetector d(MapDetectorOptions(MapKind::kRows));
    cv::Mat row(1, d.RowWidth(), d.RowType());
    for (int i = 0; i < 40; ++i) {
      rng.fill(row, cv::RNG::UNIFORM, 0, 256);
      d.AddDescriptor(row);
    }
    d.SaveMap(dir + "/rows.map");
    // The same map cut short, and with one byte of its rows changed (checksum wrong).
    const std::string bytes = ReadFile(dir + "/rows.map");
    WriteFile(dir + "/rows_truncated.map", bytes.substr(0, bytes.size() / 2));
    std::string flipped = bytes;
    flipped[bytes.size() - 100] ^= 0x20;
    WriteFile(dir + "/rows_flipped.map", flipped);
  }
  {  // 6 HOG rows (36 floats).
    OnlineDetector d(MapDetectorOptions(MapKind::kFloat));
    cv::Mat row(1, d.RowWidth(), d.RowType());
    for (int i = 0; i < 6; ++i) {
      rng.fill(row, cv::RNG::UNIFORM, 0.0, 1.0);
      d.AddDescriptor(row);
    }
    d.SaveMap(dir + "/float.map");
  }
  {  // 6 rows computed elsewhere (8 floats).
    OnlineDetector d(MapDetectorOptions(MapKind::kGiven));
    d.StartSession("given", "2026-11-29T00:00:00Z");
    cv::Mat rows(6, d.RowWidth(), d.RowType());
    rng.fill(rows, cv::RNG::UNIFORM, 0.0, 1.0);
    d.AddToMap(rows);
    d.SaveMap(dir + "/given.map");
  }
  {  // 3 frames with their ORB features.
    OnlineDetector d(MapDetectorOptions(MapKind::kVerifying));
    for (int i = 0; i < 3; ++i) d.AddFrame(MapFrame(i));
    d.SaveMap(dir + "/verifying.map");
  }
  {  // An empty map.
    OnlineDetector d(MapDetectorOptions(MapKind::kRows));
    d.SaveMap(dir + "/empty.map");
  }
  {  // 24 frames of LDB and SAD rows in two sessions, with their files, tuned.
    OnlineDetector d(MapDetectorOptions(MapKind::kSeveral));
    for (const char* session : {"a", "b"}) {
      d.StartSession(session, "2026-11-29T00:00:00Z");
      std::vector<cv::Mat> frames;
      std::vector<std::string> names;
      for (int i = 0; i < 12; ++i) {
        frames.push_back(MapFrame(i));
        names.push_back(std::string(session) + std::to_string(i) + ".png");
      }
      d.AddImagesToMap(frames, names);
    }
    OnlineDetector::TuneOptions tune;
    tune.candidates = "Image_descriptor=LDB,SAD Image_sequences=2";
    d.Tune(tune);
    d.SaveMap(dir + "/several.map");
  }
}

// ---- Bags

// A sensor_msgs/Image of `pixels` (8 or 16 bits, 1, 3 or 4 channels) in `encoding`.
sensor_msgs::Image ImageMessage(const cv::Mat& pixels, const std::string& encoding, double t,
                                bool big_endian = false) {
  sensor_msgs::Image m;
  m.header.stamp = ros::Time(t);
  m.header.frame_id = "cam";
  m.height = static_cast<std::uint32_t>(pixels.rows);
  m.width = static_cast<std::uint32_t>(pixels.cols);
  m.encoding = encoding;
  m.is_bigendian = big_endian ? 1 : 0;
  m.step = static_cast<std::uint32_t>(pixels.cols * pixels.elemSize());
  m.data.resize(static_cast<std::size_t>(m.step) * m.height);
  for (int r = 0; r < pixels.rows; ++r) {
    std::memcpy(m.data.data() + r * m.step, pixels.ptr(r), m.step);
    if (big_endian)
      for (std::uint32_t k = 0; k + 1 < m.step; k += 2)
        std::swap(m.data[r * m.step + k], m.data[r * m.step + k + 1]);
  }
  return m;
}

cv::Mat Pixels(int type, int seed) {
  cv::Mat m(6, 8, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

// The connection header rosbag writes for messages of type T, but with a one-line message
// definition: the text of sensor_msgs/Image's (2 KB, written twice) is for tools, rosbag
// reads the type and the md5sum, and the seeds stay small. Null (rosbag's own header) when
// `full`.
template <typename T>
boost::shared_ptr<ros::M_string> ConnectionHeader(bool full) {
  if (full) return {};
  auto header = boost::make_shared<ros::M_string>();
  (*header)["type"] = ros::message_traits::datatype<T>();
  (*header)["md5sum"] = ros::message_traits::md5sum<T>();
  (*header)["message_definition"] = "# left out of the fuzzer's seed\n";
  return header;
}

// A bag with `count` messages of "/image" of `encoding` ("png": CompressedImage), and one
// std_msgs/String message of "/note"; compressed chunks with `compression`; the message
// definitions written in full or not (ConnectionHeader).
void WriteBag(const std::string& path, const std::string& encoding, int count,
              rosbag::compression::CompressionType compression, bool big_endian = false,
              bool full = false) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  std_msgs::String note;
  note.data = "seed";
  bag.write("/note", ros::Time(5.0), note, ConnectionHeader<std_msgs::String>(full));
  for (int i = 0; i < count; ++i) {
    const double t = 10.0 + 0.5 * i;
    if (encoding == "png") {
      sensor_msgs::CompressedImage m;
      m.header.stamp = ros::Time(t);
      m.format = "png";
      const std::string bytes = openable::EncodePngFile(Pixels(CV_8UC1, i));
      m.data.assign(bytes.begin(), bytes.end());
      bag.write("/image", ros::Time(t + 0.01), m,
                ConnectionHeader<sensor_msgs::CompressedImage>(full));
      continue;
    }
    const int type = encoding == "mono8"    ? CV_8UC1
                     : encoding == "mono16" ? CV_16UC1
                     : encoding == "rgb8"   ? CV_8UC3
                     : encoding == "bgra8"  ? CV_8UC4
                                            : CV_16UC3;  // rgb16
    // The second message has no header stamp: its record time stands for it.
    bag.write("/image", ros::Time(t + 0.01),
              ImageMessage(Pixels(type, i), encoding, i == 1 ? 0.0 : t, big_endian),
              ConnectionHeader<sensor_msgs::Image>(full));
  }
}

void WriteBags(const std::string& dir) {
  using rosbag::compression::BZ2;
  using rosbag::compression::LZ4;
  using rosbag::compression::Uncompressed;
  WriteBag(dir + "/mono8.bag", "mono8", 2, Uncompressed);
  WriteBag(dir + "/mono8_full_definitions.bag", "mono8", 1, Uncompressed, false, true);
  WriteBag(dir + "/rgb8.bag", "rgb8", 2, Uncompressed);
  WriteBag(dir + "/bgra8.bag", "bgra8", 1, Uncompressed);
  WriteBag(dir + "/mono16_big_endian.bag", "mono16", 2, Uncompressed, true);
  WriteBag(dir + "/rgb16.bag", "rgb16", 1, Uncompressed);
  WriteBag(dir + "/png.bag", "png", 2, Uncompressed);
  WriteBag(dir + "/mono8_bz2.bag", "mono8", 2, BZ2);
  WriteBag(dir + "/mono8_lz4.bag", "mono8", 2, LZ4);
  {  // "/image" of another type.
    rosbag::Bag bag(dir + "/string_topic.bag", rosbag::bagmode::Write);
    std_msgs::String s;
    s.data = "not an image";
    bag.write("/image", ros::Time(1.0), s, ConnectionHeader<std_msgs::String>(false));
  }
  // A recording cut short (no index), and a bag with a byte of its index changed.
  const std::string bytes = ReadFile(dir + "/mono8.bag");
  WriteFile(dir + "/mono8_truncated.bag", bytes.substr(0, bytes.size() - 200));
  std::string flipped = bytes;
  flipped[bytes.size() - 30] ^= 0x01;
  WriteFile(dir + "/mono8_flipped_index.bag", flipped);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_FOLDER (writes CORPUS_FOLDER/map and /bag)\n", argv[0]);
    return 2;
  }
  const std::string corpus = argv[1];
  std::filesystem::create_directories(corpus + "/map");
  std::filesystem::create_directories(corpus + "/bag");
  WriteMaps(corpus + "/map");
  WriteBags(corpus + "/bag");
  return 0;
}
