// libFuzzer target: arbitrary bytes as the contents of an image file, decoded by
// DecodeImageBytes (the decoding part of ReadImageFile: our PNG chunk and CRC walk, the JPEG
// end check, OpenCV's codecs, OpenImageIO from memory). The expected outcomes are a frame of
// the documented format (CV_32FC1 or CV_32FC3, values in [0, 1]) or InputError; any other
// exception, a crash, a wrong frame or a sanitizer report is a finding.
// Built with -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "OpenABLE/io/frame_source.h"
#include "tests/fuzz/frame_check.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  openable::fuzz::LimitDecodedPixels();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes = openable::fuzz::Bytes(data, size);
  cv::Mat frame;
  if (openable::fuzz::Refuses([&] { frame = openable::DecodeImageBytes(bytes, "fuzz"); })) return 0;
  openable::fuzz::CheckFrame(frame, "image_fuzzer");
  return 0;
}
