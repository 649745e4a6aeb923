// libFuzzer target: arbitrary bytes as a ROS 1 bag, written to a temporary file and opened as
// a run opens one (OpenBag, OpenABLE/io/frame_source.h: the module libopenable_rosbag.so over
// Debian's rosbag_storage) with the topic "/image", the topic of every seed (of type
// sensor_msgs/Image in some, sensor_msgs/CompressedImage in others); then every frame is read
// (Read: the message deserialised, its pixels decoded) and its time asked for (Timestamp).
// The expected outcomes are frames of the documented format (CV_32FC1 or CV_32FC3, values in
// [0, 1]) or one InputError line naming the bag; any other exception, a crash or a sanitizer
// report is a finding. Built with -DOPENABLE_BUILD_FUZZERS=ON (clang) when the rosbag module
// is built; see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "OpenABLE/io/frame_source.h"
#include "tests/fuzz/frame_check.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  openable::fuzz::LimitDecodedPixels();  // compressed images are decoded as image files are
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using openable::fuzz::Refuses;
  const openable::fuzz::TempFile file(openable::fuzz::Bytes(data, size), ".bag");
  std::unique_ptr<openable::FrameSource> source;
  const auto open = [&] {
    source = openable::OpenBag(file.Path(), "/image", 0, -1, "Bag_path", "Bag_topic");
  };
  if (Refuses(open, file.Path())) return 0;
  for (int i = 0; i < source->Size(); ++i) {
    cv::Mat frame;
    if (!Refuses([&] { frame = source->Read(i); }, file.Path()))
      openable::fuzz::CheckFrame(frame, "bag_fuzzer");
    Refuses([&] { source->Timestamp(i); }, file.Path());
  }
  return 0;
}
