// libFuzzer target: arbitrary bytes as the contents of an image file, decoded by
// DecodeImageBytes (the decoding part of ReadImageFile: our PNG chunk and CRC walk, the JPEG
// end check, OpenCV's codecs, OpenImageIO from memory). The expected outcomes are a frame of
// the documented format (CV_32FC1 or CV_32FC3, values in [0, 1]) or InputError; any other
// exception, a crash, a wrong frame or a sanitizer report is a finding.
// Built with -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <opencv2/core.hpp>

#include "OpenABLE/io/frame_source.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // A header may announce a huge image; OpenCV's decoders refuse more pixels than this
  // (default 2^30), which keeps the fuzzer under its memory limit.
  setenv("OPENCV_IO_MAX_IMAGE_PIXELS", "4000000", 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes = openable::fuzz::Bytes(data, size);
  cv::Mat frame;
  if (openable::fuzz::Refuses([&] { frame = openable::DecodeImageBytes(bytes, "fuzz"); }))
    return 0;
  const bool format_ok = !frame.empty() && (frame.type() == CV_32FC1 || frame.type() == CV_32FC3);
  double lo = 0.0;
  double hi = 0.0;
  if (format_ok) cv::minMaxLoc(frame.reshape(1), &lo, &hi);
  if (!format_ok || !(lo >= 0.0 && hi <= 1.0)) {
    std::fprintf(stderr, "image_fuzzer: decoded frame of type %d, %d x %d, values [%g, %g]\n",
                 frame.type(), frame.cols, frame.rows, lo, hi);
    std::abort();
  }
  return 0;
}
