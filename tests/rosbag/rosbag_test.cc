// ROS 1 bags as input (Frame_mode 3, OpenBag): bags written here with Debian's rosbag_storage
// from real frames of ../shared/datasets, read back by Test_OpenABLE and compared with the same
// frames read from their folders.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <boost/make_shared.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/io/frame_source.h"
#include "tests/e2e/e2e_support.h"
#include "tests/tools/euroc_calibration.h"

namespace openable {
namespace {

using e2e::Outcome;
using e2e::ReadAll;
using e2e::ReadJson;
using e2e::RunProgram;
namespace fs = std::filesystem;

std::string Kitti() { return testing::DatasetsDir() + "/kitti00_first1700"; }
std::string Sample() { return testing::SampleDir(); }

bool OneLine(const std::string& s) { return !s.empty() && s.find('\n') == s.size() - 1; }

// The images of `folder` in natural order, [0, count).
std::vector<std::string> Frames(const std::string& folder, int count) {
  std::vector<std::string> paths = ListImages(folder, "");
  if (static_cast<int>(paths.size()) > count) paths.resize(count);
  return paths;
}

// A sensor_msgs/Image of `image` (8-bit grey or BGR) in `encoding`.
sensor_msgs::Image ImageMessage(const cv::Mat& image, const std::string& encoding, double t) {
  cv::Mat pixels = image;
  if (encoding == "rgb8") cv::cvtColor(image, pixels, cv::COLOR_BGR2RGB);
  if (encoding == "mono16") image.convertTo(pixels, CV_16U, 257.0);  // v -> v * 257
  sensor_msgs::Image m;
  m.header.stamp = ros::Time(t);
  m.header.frame_id = "cam0";
  m.height = pixels.rows;
  m.width = pixels.cols;
  m.encoding = encoding;
  m.is_bigendian = 0;
  m.step = static_cast<std::uint32_t>(pixels.cols * pixels.elemSize());
  m.data.resize(static_cast<std::size_t>(m.step) * m.height);
  for (int r = 0; r < pixels.rows; ++r)
    std::memcpy(m.data.data() + r * m.step, pixels.ptr(r), m.step);
  return m;
}

// Writes `frames` to `topic` of `bag` as `encoding` ("compressed": the PNG file's own bytes as
// a sensor_msgs/CompressedImage), stamped times[i]; recorded 5 ms after each stamp.
void WriteTopic(rosbag::Bag& bag, const std::string& topic, const std::vector<std::string>& frames,
                const std::string& encoding, const std::vector<double>& times) {
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const ros::Time record(times[i] + 0.005);
    if (encoding == "compressed") {
      sensor_msgs::CompressedImage m;
      m.header.stamp = ros::Time(times[i]);
      m.format = "png";
      const std::string bytes = ReadAll(frames[i]);
      m.data.assign(bytes.begin(), bytes.end());
      bag.write(topic, record, m);
      continue;
    }
    const bool grey = encoding == "mono8" || encoding == "mono16";
    const cv::Mat image = cv::imread(frames[i], grey ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty()) << frames[i];
    bag.write(topic, record, ImageMessage(image, encoding, times[i]));
  }
}

std::vector<double> KittiTimes(int count) {
  std::ifstream in(Kitti() + "/times.txt");
  std::vector<double> t;
  double v;
  while (static_cast<int>(t.size()) < count && in >> v) t.push_back(1.4e9 + v);  // a ROS epoch
  return t;
}

std::string Written(const std::string& dir, const std::vector<std::string>& args) {
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  EXPECT_EQ(o.status, 0) << o.err;
  return o.err;
}

// The bytes of the .npy a run of Test_OpenABLE with `args` then `common` writes to `npy`.
std::string MatrixOf(const std::string& dir, std::vector<std::string> args,
                     const std::vector<std::string>& common, const std::string& npy) {
  args.insert(args.end(), common.begin(), common.end());
  args.insert(args.end(), {"--set", "Npy_name=" + npy});
  Written(dir, args);
  return ReadAll(dir + "/" + npy);
}

// The bar: KITTI 00 frames 0-299 from a bag give the matrix of the image folder, bit for bit,
// whether stored raw (mono8) or as the PNG files themselves (CompressedImage).
TEST(RosBag, Kitti300FramesGiveTheFolderMatrixBitForBit) {
  OPENABLE_REQUIRE_PATH(Kitti());
  const std::string dir = testing::TempDir();
  const std::vector<std::string> frames = Frames(Kitti() + "/image_0", 300);
  ASSERT_EQ(frames.size(), 300u);
  const std::vector<double> times = KittiTimes(300);
  {
    rosbag::Bag bag(dir + "/kitti.bag", rosbag::bagmode::Write);
    WriteTopic(bag, "/kitti/camera_gray_left/image_raw", frames, "mono8", times);
    WriteTopic(bag, "/kitti/camera_gray_left/image_png", frames, "compressed", times);
  }
  const std::vector<std::string> common = {
      "--set", "Image_sequences=10", "--set", "Png_name=", "--set", "Ground_truth_type="};
  auto run = [&](const std::string& npy, const std::vector<std::string>& args) {
    return MatrixOf(dir, args, common, npy);
  };
  const std::string folder = run(
      "folder.npy", {"--set", "Images_path=" + Kitti() + "/image_0", "--set", "Final_image=300"});
  const std::string raw = run("raw.npy", {"--set", "Frame_mode=3", "--set", "Bag_path=kitti.bag",
                                          "--set", "Bag_topic=/kitti/camera_gray_left/image_raw",
                                          "--set", "Timestamps_name=times.txt"});
  const std::string png = run("png.npy", {"--set", "Frame_mode=3", "--set", "Bag_path=kitti.bag",
                                          "--set", "Bag_topic=/kitti/camera_gray_left/image_png"});
  ASSERT_GT(folder.size(), 300u * 300u * 4u);
  EXPECT_TRUE(folder == raw) << "mono8 bag differs from the folder";
  EXPECT_TRUE(folder == png) << "CompressedImage bag differs from the folder";
  // The frames kept their message stamps.
  std::ifstream in(dir + "/times.txt");
  std::string header;
  std::getline(in, header);
  for (int i = 0; i < 300; ++i) {
    int row = -1;
    double t = 0;
    ASSERT_TRUE(in >> row >> t) << i;
    EXPECT_EQ(row, i);
    EXPECT_NEAR(t, times[i], 1e-6) << i;
  }
}

// Colour encodings give the folder's frames: bgr8 and rgb8 as stored, mono16 scaled.
TEST(RosBag, EncodingsDecodeToTheFramesOfTheFiles) {
  OPENABLE_REQUIRE_PATH(testing::DatasetsDir() + "/gardens_point");
  const std::string dir = testing::TempDir();
  const std::vector<std::string> colour =
      Frames(testing::DatasetsDir() + "/gardens_point/day_left", 3);
  const std::vector<double> times = {10.0, 10.5, 11.0};
  {
    rosbag::Bag bag(dir + "/c.bag", rosbag::bagmode::Write);
    WriteTopic(bag, "/bgr", colour, "bgr8", times);
    WriteTopic(bag, "/rgb", colour, "rgb8", times);
    WriteTopic(bag, "/mono16", colour, "mono16", times);
  }
  for (const std::string topic : {"/bgr", "/rgb"}) {
    const auto source = OpenBag(dir + "/c.bag", topic, 0, -1, "Bag_path", "Bag_topic");
    ASSERT_EQ(source->Size(), 3);
    for (int i = 0; i < 3; ++i) {
      // The pixels written (OpenCV's decoding of the JPEG file), as a frame: BGR in [0, 1].
      cv::Mat expected;
      cv::imread(colour[i], cv::IMREAD_COLOR).convertTo(expected, CV_32F, 1.0 / 255.0);
      EXPECT_EQ(cv::norm(source->Read(i), expected, cv::NORM_INF), 0.0) << topic << " " << i;
      EXPECT_NEAR(source->Timestamp(i), times[i], 1e-9);
    }
    EXPECT_EQ(source->FrameName(1), "c.bag:" + topic + "#1");
  }
  const auto mono16 = OpenBag(dir + "/c.bag", "/mono16", 1, 3, "Bag_path", "Bag_topic");
  ASSERT_EQ(mono16->Size(), 2);
  const cv::Mat grey = cv::imread(colour[1], cv::IMREAD_GRAYSCALE);
  cv::Mat expected;
  grey.convertTo(expected, CV_32F, 1.0 / 255.0);  // v * 257 / 65535 = v / 255
  EXPECT_LT(cv::norm(mono16->Read(0), expected, cv::NORM_INF), 1e-6);
  EXPECT_NEAR(mono16->Timestamp(1), times[2], 1e-9);  // the range starts at message 1
}

// A second traversal from a second topic gives the matrix of two folders.
TEST(RosBag, SecondTraversalFromATopicOrABag) {
  const std::string dir = testing::TempDir();
  const std::vector<std::string> summer = Frames(Sample() + "/summer", 60);
  const std::vector<std::string> winter = Frames(Sample() + "/winter", 60);
  std::vector<double> times(60);
  for (int i = 0; i < 60; ++i) times[i] = 100 + i;
  {
    rosbag::Bag bag(dir + "/both.bag", rosbag::bagmode::Write);
    WriteTopic(bag, "/summer", summer, "bgr8", times);
    WriteTopic(bag, "/winter", winter, "bgr8", times);
    rosbag::Bag other(dir + "/winter.bag", rosbag::bagmode::Write);
    WriteTopic(other, "/cam", winter, "bgr8", times);
  }
  const std::vector<std::string> common = {
      "--set", "Image_sequences=5", "--set", "Png_name=",
      "--set", "Final_image=60",    "--set", "Ground_truth_type="};
  auto run = [&](const std::string& npy, const std::vector<std::string>& args) {
    return MatrixOf(dir, args, common, npy);
  };
  const std::string folders =
      run("folders.npy", {"--set", "Images_path=" + Sample() + "/summer", "--set",
                          "Images_path_2=" + Sample() + "/winter"});
  const std::string topics =
      run("topics.npy", {"--set", "Frame_mode=3", "--set", "Bag_path=both.bag", "--set",
                         "Bag_topic=/summer", "--set", "Bag_topic_2=/winter"});
  const std::string bags = run("bags.npy", {"--set", "Frame_mode=3", "--set", "Bag_path=both.bag",
                                            "--set", "Bag_topic=/summer", "--set",
                                            "Bag_path_2=winter.bag", "--set", "Bag_topic_2=/cam"});
  ASSERT_GT(folders.size(), 120u * 120u * 4u);
  EXPECT_TRUE(folders == topics);
  EXPECT_TRUE(folders == bags);
}

// Stereo from two topics (Camera_type 1, Bag_topic_right) gives the matrix of the two folders.
TEST(RosBag, StereoPairsFromTwoTopicsGiveTheFoldersMatrix) {
  const std::string euroc = testing::DatasetsDir() + "/euroc_stereo_pairs";
  OPENABLE_REQUIRE_PATH(euroc);
  const std::string dir = testing::TempDir();
  std::vector<std::string> left, right;
  fs::create_directories(dir + "/left");
  fs::create_directories(dir + "/right");
  for (int i = 0; i < 4; ++i) {
    left.push_back(dir + "/left/left_img_" + std::to_string(i) + ".png");
    right.push_back(dir + "/right/right_img_" + std::to_string(i) + ".png");
    fs::copy_file(euroc + "/left_img_" + std::to_string(i) + ".png", left.back());
    fs::copy_file(euroc + "/right_img_" + std::to_string(i) + ".png", right.back());
  }
  ASSERT_TRUE(testing::WriteEurocCalibration(euroc, dir + "/calibration.yaml"));
  const std::vector<double> times = {5.0, 5.05, 5.1, 5.15};
  {
    rosbag::Bag bag(dir + "/stereo.bag", rosbag::bagmode::Write);
    WriteTopic(bag, "/cam0/image_raw", left, "mono8", times);
    WriteTopic(bag, "/cam1/image_raw", right, "mono8", times);
    WriteTopic(bag, "/cam1/short", std::vector<std::string>(right.begin(), right.begin() + 3),
               "mono8", times);
  }
  const std::vector<std::string> common = {"--set", "Camera_type=1",
                                           "--set", "Calibration_path=calibration.yaml",
                                           "--set", "Image_descriptor=D-LDB",
                                           "--set", "Ldb_bits=1386",
                                           "--set", "Png_name=",
                                           "--set", "Ground_truth_type="};
  auto run = [&](const std::string& npy, const std::vector<std::string>& args) {
    return MatrixOf(dir, args, common, npy);
  };
  const std::string folders =
      run("folders.npy", {"--set", "Images_path_left=left", "--set", "Images_path_right=right"});
  const std::string topics =
      run("topics.npy", {"--set", "Frame_mode=3", "--set", "Bag_path=stereo.bag", "--set",
                         "Bag_topic=/cam0/image_raw", "--set", "Bag_topic_right=/cam1/image_raw"});
  ASSERT_GT(folders.size(), 4u * 4u * 4u);
  EXPECT_TRUE(folders == topics);
  const Outcome o = RunProgram(
      testing::TestOpenableExe(),
      {"--set", "Camera_type=1", "--set", "Calibration_path=calibration.yaml", "--set",
       "Frame_mode=3", "--set", "Bag_path=stereo.bag", "--set", "Bag_topic=/cam0/image_raw",
       "--set", "Bag_topic_right=/cam1/short", "--set", "Npy_name=out/m.npy"},
      dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("Bag_topic/Bag_topic_right: 4 left images but 3 right images"),
            std::string::npos)
      << o.err;
}

// TUM ground truth is associated by time: KITTI's poses written as a TUM file with stamps 4 ms
// off the frames' give the evaluation of the same poses in KITTI's format read line by line.
// Every 10th frame of 0-1699, so that the loops of KITTI 00 (frames 1570 on) are in.
TEST(RosBag, TumGroundTruthAssociatesByTime) {
  OPENABLE_REQUIRE_PATH(Kitti());
  const std::string dir = testing::TempDir();
  const int stride = 10, n = 170;
  const std::vector<std::string> all = Frames(Kitti() + "/image_0", n * stride);
  const std::vector<double> all_times = KittiTimes(n * stride);
  ASSERT_EQ(all.size(), static_cast<std::size_t>(n * stride));
  std::vector<std::string> frames;
  std::vector<double> times;
  for (int i = 0; i < n; ++i) {
    frames.push_back(all[i * stride]);
    times.push_back(all_times[i * stride]);
  }
  {
    rosbag::Bag bag(dir + "/kitti.bag", rosbag::bagmode::Write);
    WriteTopic(bag, "/cam", frames, "mono8", times);
  }
  // 3x4 camera-to-world per line -> "t tx ty tz qx qy qz qw" for every frame (read line by line,
  // its first 170 lines would be the wrong poses), and the bag's frames' poses as KITTI.
  std::ifstream kitti(Kitti() + "/poses/00_first1700.txt");
  std::ofstream tum(dir + "/truth_tum.txt");
  tum.precision(17);
  std::ofstream head(dir + "/truth_kitti.txt");
  head.precision(17);
  for (int i = 0; i < n * stride; ++i) {
    cv::Matx34d p;
    for (int k = 0; k < 12; ++k) ASSERT_TRUE(kitti >> p.val[k]);
    if (i % stride == 0)
      for (int k = 0; k < 12; ++k) head << p.val[k] << (k == 11 ? "\n" : " ");
    Eigen::Matrix3d r;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) r(a, b) = p(a, b);
    const Eigen::Quaterniond q(r);
    const double x = q.x(), y = q.y(), z = q.z(), w = q.w();
    tum << all_times[i] + 0.004 << " " << p(0, 3) << " " << p(1, 3) << " " << p(2, 3) << " " << x
        << " " << y << " " << z << " " << w << "\n";
  }
  tum.close();
  head.close();
  const std::vector<std::string> common = {
      "--set", "Frame_mode=3",          "--set", "Bag_path=kitti.bag",  "--set", "Bag_topic=/cam",
      "--set", "Image_sequences=3",     "--set", "Png_name=",           "--set", "Exclusion=5",
      "--set", "Ground_truth_radius=5", "--set", "Ground_truth_axes=xz"};
  auto evaluate = [&](const std::string& name, const std::vector<std::string>& truth) {
    std::vector<std::string> args = common;
    args.insert(args.end(), truth.begin(), truth.end());
    args.insert(args.end(), {"--set", "Evaluation_name=" + name});
    Written(dir, args);
    return ReadAll(dir + "/" + name + "_per_query.csv");
  };
  const std::string by_line = evaluate(
      "line", {"--set", "Ground_truth_type=kitti", "--set", "Ground_truth=truth_kitti.txt"});
  const std::string by_time =
      evaluate("time", {"--set", "Ground_truth_type=tum", "--set", "Ground_truth=truth_tum.txt"});
  EXPECT_EQ(by_line, by_time);
  // Not vacuous: the loops of KITTI 00 are there.
  const Json evaluation = ReadJson(dir + "/time.json");
  const Json& per_query = evaluation.at("runs").at(0).at("per_query");
  EXPECT_GT(per_query.at("positive_queries").get<int>(), 5) << per_query.dump();
  // SNAPS on the TUM trajectory of every frame: the loops of the bag's saved matrix map to the
  // poses by time through Timestamps_name (pose 10 i for row i), not to pose i.
  Written(dir, {"--set", "Frame_mode=3", "--set", "Bag_path=kitti.bag", "--set", "Bag_topic=/cam",
                "--set", "Image_sequences=3", "--set", "Png_name=", "--set", "Npy_name=m.npy",
                "--set", "Timestamps_name=times.txt"});
  auto snaps_loops = [&](const std::string& prefix, bool by_time) {
    std::vector<std::string> args = {"--set", "Snaps_trajectory=truth_tum.txt",
                                     "--set", "Snaps_trajectory_format=tum",
                                     "--set", "Snaps_loops=matrix",
                                     "--set", "Snaps_loops_file=m.npy",
                                     "--set", "Snaps_matrix_threshold=0.6",
                                     "--set", "Snaps_frame_distance=50",
                                     "--set", "Snaps_corrector=discounted",
                                     "--set", "Snaps_output_name=" + prefix};
    if (by_time) args.insert(args.end(), {"--set", "Snaps_frame_times=times.txt"});
    const Outcome o = RunProgram(testing::OpenableSnapsExe(), args, dir);
    EXPECT_EQ(o.status, 0) << o.err;
    std::vector<std::pair<int, int>> loops;
    std::ifstream in(dir + "/" + prefix + "_loops.csv");
    std::string line;
    while (std::getline(in, line)) {
      int q = 0, r = 0;
      if (line.empty() || line[0] == '#' || std::sscanf(line.c_str(), "%d,%d", &q, &r) != 2)
        continue;
      loops.emplace_back(q, r);
    }
    return loops;
  };
  const auto loops_by_time = snaps_loops("snaps_time", true);
  const auto loops_by_row = snaps_loops("snaps_row", false);
  ASSERT_GT(loops_by_time.size(), 5u);
  ASSERT_EQ(loops_by_time.size(), loops_by_row.size());
  for (std::size_t k = 0; k < loops_by_time.size(); ++k) {
    EXPECT_EQ(loops_by_time[k].first, stride * loops_by_row[k].first) << k;  // row i: pose 10 i
    EXPECT_EQ(loops_by_time[k].second, stride * loops_by_row[k].second) << k;
  }

  // 4 ms off is outside a 3 ms tolerance: the frame is named.
  const Outcome o =
      RunProgram(testing::TestOpenableExe(),
                 {"--set", "Frame_mode=3", "--set", "Bag_path=kitti.bag", "--set", "Bag_topic=/cam",
                  "--set", "Ground_truth_type=tum", "--set", "Ground_truth=truth_tum.txt", "--set",
                  "Ground_truth_time_tolerance=0.003", "--set", "Npy_name=out/m.npy"},
                 dir);
  EXPECT_EQ(o.status, 1);
  // The frames' times are known once they are read: progress lines come first, then the one
  // error line, last.
  const std::size_t error = o.err.find("Test_OpenABLE: error: ");
  ASSERT_NE(error, std::string::npos) << o.err;
  EXPECT_TRUE(OneLine(o.err.substr(error))) << o.err;
  EXPECT_NE(o.err.find("no pose within 0.003 s of frame 0 (time "), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// Bad bags: one line naming the bag, the topic and what was expected; nothing written.
TEST(RosBag, BadBagsAreOneLineNamingBagAndTopic) {
  const std::string dir = testing::TempDir();
  const std::vector<std::string> frames = Frames(Sample() + "/summer", 20);
  std::vector<double> times(20);
  for (int i = 0; i < 20; ++i) times[i] = 1 + i;
  {
    rosbag::Bag bag(dir + "/good.bag", rosbag::bagmode::Write);
    WriteTopic(bag, "/cam0/image_raw", frames, "bgr8", times);
    std_msgs::String text;
    text.data = "not an image";
    bag.write("/status", ros::Time(1), text);
  }
  // Truncated: the first half of the file (a recording cut short: no index).
  const std::string good = ReadAll(dir + "/good.bag");
  std::ofstream(dir + "/cut.bag", std::ios::binary) << good.substr(0, good.size() / 2);
  std::ofstream(dir + "/text.bag") << "#ROSBAG V2.0\nnot really\n";
  struct Case {
    std::string bag, topic, expected;
  };
  const std::vector<Case> cases = {
      {"good.bag", "/cam1/image_raw",
       "Bag_topic: topic \"/cam1/image_raw\" is not in bag \"good.bag\"; expected an image topic "
       "of the bag: /cam0/image_raw (sensor_msgs/Image); other topics: /status "
       "(std_msgs/String)"},
      {"good.bag", "/status",
       "Bag_topic: topic \"/status\" of bag \"good.bag\" holds std_msgs/String; expected "
       "sensor_msgs/Image or sensor_msgs/CompressedImage"},
      {"cut.bag", "/cam0/image_raw", "Bag_path: bag \"cut.bag\" cannot be read ("},
      {"text.bag", "/cam0/image_raw", "Bag_path: bag \"text.bag\" cannot be read ("},
      {"absent.bag", "/cam0/image_raw", "Bag_path: bag \"absent.bag\" does not exist"},
  };
  for (const Case& c : cases) {
    const Outcome o = RunProgram(
        testing::TestOpenableExe(),
        {"--set", "Frame_mode=3", "--set", "Bag_path=" + c.bag, "--set", "Bag_topic=" + c.topic,
         "--set", "Npy_name=out/m.npy", "--set", "Ground_truth_type="},
        dir);
    EXPECT_EQ(o.status, 1) << c.bag << " " << o.err;
    EXPECT_TRUE(OneLine(o.err)) << o.err;
    EXPECT_NE(o.err.find(c.expected), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir + "/out")) << c.bag;
  }
  // Keys that need each other.
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {"--set", "Frame_mode=3", "--set", "Bag_path=good.bag"}, dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("Bag_topic: empty; expected the image topic"), std::string::npos) << o.err;
  const Outcome t = RunProgram(testing::TestOpenableExe(),
                               {"--set", "Images_path=" + Sample() + "/summer", "--set",
                                "Timestamps_name=t.txt", "--set", "Ground_truth_type="},
                               dir);
  EXPECT_EQ(t.status, 1);
  EXPECT_NE(t.err.find("Timestamps_name: \"t.txt\" with Frame_mode 0"), std::string::npos) << t.err;
}

// Messages that state the condition that failed: a topic that mixes two message types (each
// message on its own is fine), an image message of 0 x 0 pixels (not "step >= width x ..."
// conditions that both hold), an image whose step is shorter than a row, and data shorter than
// height x step.
TEST(RosBag, MessagesStateTheConditionThatFailed) {
  const std::string dir = testing::TempDir();
  const std::vector<std::string> frames = Frames(Sample() + "/summer", 3);
  const cv::Mat grey = cv::imread(frames[0], cv::IMREAD_GRAYSCALE);
  std_msgs::String text;
  text.data = "not an image";
  {
    // As rosbag record files two publishers of the topic: a connection each, with its type.
    rosbag::Bag bag(dir + "/mixed.bag", rosbag::bagmode::Write);
    auto header = [](const std::string& caller, const std::string& type) {
      auto h = boost::make_shared<ros::M_string>();
      (*h)["callerid"] = caller;
      (*h)["type"] = type;
      return h;
    };
    bag.write("/cam0/image_raw", ros::Time(1), ImageMessage(grey, "mono8", 1),
              header("/camera", "sensor_msgs/Image"));
    bag.write("/cam0/image_raw", ros::Time(2), text, header("/chatter", "std_msgs/String"));
  }
  {
    // rosbag's writer without connection headers files the text under the topic's first
    // connection, a sensor_msgs/Image one: only decoding can tell.
    rosbag::Bag bag(dir + "/misfiled.bag", rosbag::bagmode::Write);
    bag.write("/cam0/image_raw", ros::Time(1), ImageMessage(grey, "mono8", 1));
    bag.write("/cam0/image_raw", ros::Time(2), text);
  }
  sensor_msgs::Image empty = ImageMessage(grey, "mono8", 1);
  empty.width = 0;
  empty.height = 0;
  empty.step = 0;
  empty.data.clear();
  sensor_msgs::Image short_step = ImageMessage(grey, "mono8", 1);
  short_step.step = short_step.width - 1;
  sensor_msgs::Image short_data = ImageMessage(grey, "mono8", 1);
  short_data.data.resize(short_data.data.size() - 1);
  const std::vector<std::pair<std::string, sensor_msgs::Image>> images = {
      {"empty", empty}, {"short_step", short_step}, {"short_data", short_data}};
  for (const auto& [name, message] : images) {
    rosbag::Bag bag(dir + "/" + name + ".bag", rosbag::bagmode::Write);
    bag.write("/cam0/image_raw", ros::Time(1), message);
  }
  const std::string w = std::to_string(grey.cols), h = std::to_string(grey.rows);
  struct Case {
    std::string bag, expected;
  };
  const std::vector<Case> cases = {
      {"mixed.bag",
       "Bag_topic: topic \"/cam0/image_raw\" of bag \"mixed.bag\" carries 2 message types "
       "(sensor_msgs/Image, std_msgs/String); expected one: sensor_msgs/Image or "
       "sensor_msgs/CompressedImage"},
      {"misfiled.bag",
       "does not decode as sensor_msgs/Image, the type its connection declares (a field's "
       "length runs past its 16 bytes): a message of another type written on the topic, or "
       "damage"},
      {"empty.bag",
       "message 0: the image is 0 x 0 pixels (width x height); expected at least "
       "1 x 1"},
      {"short_step.bag", "message 0: step " + std::to_string(grey.cols - 1) +
                             " bytes is shorter than a row of " + w + " x " + h + " mono8 (" + w +
                             " bytes); expected step >= width x 1 bytes"},
      {"short_data.bag", "message 0: " + std::to_string(grey.total() - 1) + " bytes of data for " +
                             w + " x " + h + " mono8 rows of step " + w +
                             "; expected height x step = " + std::to_string(grey.total()) +
                             " bytes"},
  };
  for (const Case& c : cases) {
    const Outcome o = RunProgram(
        testing::TestOpenableExe(),
        {"--set", "Frame_mode=3", "--set", "Bag_path=" + c.bag, "--set",
         "Bag_topic=/cam0/image_raw", "--set", "Npy_name=out/m.npy", "--set", "Ground_truth_type="},
        dir);
    EXPECT_EQ(o.status, 1) << c.bag << " " << o.err;
    EXPECT_TRUE(OneLine(o.err)) << o.err;
    EXPECT_NE(o.err.find(c.expected), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir + "/out")) << c.bag;
  }
}

// The bags of the bag fuzzer's corpus (tests/fuzz/corpus/bag/: written by rosbag_storage
// through tests/fuzz/write_seeds.cc, and damaged ones).
std::string FuzzBag(const std::string& name) {
  return testing::SourceDir() + "/tests/fuzz/corpus/bag/" + name;
}

// Found by tests/fuzz/bag_fuzzer.cc on its seed mono8_flipped_index.bag (mono8.bag with one byte
// of its index changed): Debian's rosbag_storage read 65 KB past a buffer of 138 bytes, since
// ros::Header::parse takes a field's length as the file gives it (AddressSanitizer:
// heap-buffer-overflow). Its reader trusts the other lengths and positions of a bag as well;
// the bags beside it, made from mono8.bag, show three: a pixel array announcing 4 GB (allocated
// and zeroed before the data is found missing), an index entry naming a byte inside a record
// (read as a record header), a time whose nanoseconds overflow its seconds (std::runtime_error
// from ros::Time). OpenBag now walks a bag before rosbag_storage reads it
// (OpenABLE/io/rosbag_check.h): each is one line naming the bag and the defect.
TEST(RosBag, DamagedBagsAreRefusedBeforeRosbagStorageReadsThem) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"mono8_flipped_index.bag",
       "its chunk info record at byte 5314's header has a field of 65544 bytes where 8 are left"},
      {"image_data_length.bag",
       "the message of topic \"/image\" at byte 389 of its chunk at byte 4117 does not decode "
       "as sensor_msgs/Image, the type its connection declares (a field's length runs past its "
       "93 bytes)"},
      {"index_offset_inside_record.bag",
       "an index entry of its chunk at byte 4117 names byte 393 of its content, where no "
       "message record begins"},
      {"index_time_overflow.bag",
       "its index record at byte 4900 has a time of 4294967295 s and 4294967295 ns"},
      {"mono8_truncated.bag", "its connection record at byte 5145 is cut short"},
  };
  for (const auto& [name, defect] : cases) {
    const std::string path = FuzzBag(name);
    testing::ExpectInputError([&] { OpenBag(path, "/image", 0, -1, "Bag_path", "Bag_topic"); },
                              {"Bag_path: bag " + testing::Q(path) + " cannot be read (" + defect,
                               "expected a complete ROS 1 bag of format 2.0"});
  }
  // Not bags of format 2.0, and a bag without index.
  const std::string dir = testing::TempDir();
  std::ofstream(dir + "/old.bag") << "#ROSBAG V1.2\nrecords\n";
  std::ofstream(dir + "/text.bag") << "a text\n";
  std::string unindexed = ReadAll(FuzzBag("mono8.bag"));
  unindexed.replace(unindexed.find("index_pos=") + 10, 8, std::string(8, '\0'));
  std::ofstream(dir + "/unindexed.bag", std::ios::binary) << unindexed;
  for (const auto& [name, defect] : std::vector<std::pair<std::string, std::string>>{
           {"old.bag", "it is a bag of format \"1.2\"; OpenABLE reads format 2.0"},
           {"text.bag", "it is not a ROS 1 bag"},
           {"unindexed.bag", "it has no index: a recording cut short (rosbag reindex"}})
    testing::ExpectInputError(
        [&] { OpenBag(dir + "/" + name, "/image", 0, -1, "Bag_path", "Bag_topic"); },
        {testing::Q(dir + "/" + name) + " cannot be read (" + defect});
}

// A connection whose type holds control characters (a damaged bag the fuzzer found) is named
// in one line, its bytes escaped.
TEST(RosBag, TextOfTheBagIsEscapedInMessages) {
  const std::string path = FuzzBag("datatype_with_control_characters.bag");
  const std::string message =
      testing::InputErrorMessage([&] { OpenBag(path, "/image", 0, -1, "Bag_path", "Bag_topic"); });
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find("Bag_topic: topic \"/image\" of bag " + testing::Q(path) + " holds s"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("\\n\\x00"), std::string::npos) << message;  // escaped
}

// The bags rosbag_storage writes pass the walk, whatever their chunks' compression and the
// messages' encodings: every frame of the fuzzer's seeds is read, with its time.
TEST(RosBag, FuzzerSeedsWrittenByRosbagAreRead) {
  for (const std::string name :
       {"mono8.bag", "mono8_bz2.bag", "mono8_lz4.bag", "mono8_full_definitions.bag", "rgb8.bag",
        "bgra8.bag", "mono16_big_endian.bag", "rgb16.bag", "png.bag"}) {
    const auto source = OpenBag(FuzzBag(name), "/image", 0, -1, "Bag_path", "Bag_topic");
    ASSERT_GE(source->Size(), 1) << name;
    for (int i = 0; i < source->Size(); ++i) {
      const cv::Mat frame = source->Read(i);
      EXPECT_EQ(frame.size(), cv::Size(8, 6)) << name << " " << i;
      EXPECT_EQ(frame.depth(), CV_32F) << name << " " << i;
      EXPECT_NEAR(source->Timestamp(i), 10.0 + 0.5 * i, 0.011) << name << " " << i;
    }
  }
}

}  // namespace
}  // namespace openable
