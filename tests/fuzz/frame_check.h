// The frame checks of the fuzzers that decode images (tests/fuzz/image_fuzzer.cc,
// tests/fuzz/bag_fuzzer.cc).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <string>

namespace openable::fuzz {

// A header may announce a huge image; OpenCV's decoders (and OpenABLE's own check before
// OpenImageIO allocates) refuse more pixels than this (default 2^30), which keeps a fuzzer
// under its memory limit. Called from LLVMFuzzerInitialize.
inline void LimitDecodedPixels() { setenv("OPENCV_IO_MAX_IMAGE_PIXELS", "4000000", 1); }

// Aborts (a finding) unless `frame` has the format of every frame source: CV_32FC1 or CV_32FC3,
// values in [0, 1]. `who` names the fuzzer in the message.
inline void CheckFrame(const cv::Mat& frame, const char* who) {
  const bool format_ok = !frame.empty() && (frame.type() == CV_32FC1 || frame.type() == CV_32FC3);
  double lo = 0.0;
  double hi = 0.0;
  if (format_ok) cv::minMaxLoc(frame.reshape(1), &lo, &hi);
  if (!format_ok || !(lo >= 0.0 && hi <= 1.0)) {
    std::fprintf(stderr, "%s: decoded frame of type %d, %d x %d, values [%g, %g]\n", who,
                 frame.type(), frame.cols, frame.rows, lo, hi);
    std::abort();
  }
}

}  // namespace openable::fuzz
