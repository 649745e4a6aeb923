// Writes circularly shifted copies of panoramas: the view of a robot at the same place facing
// the other way when the shift is half the width (bench/sussex_panoramas.sh). Every pixel
// column x of the output is column (x + shift) mod W of the input; files keep their names.
// Usage: shift_panoramas <input folder> <output folder> <fraction of the width> [count]
// count: only the first `count` images in natural order (default: all).
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "OpenABLE/io/frame_source.h"

int main(int argc, char** argv) {
  if (argc != 4 && argc != 5) {
    std::fprintf(stderr,
                 "usage: shift_panoramas <input folder> <output folder> <fraction> [count]\n");
    return 2;
  }
  try {
    const std::vector<std::string> files = openable::ListImages(argv[1], "");
    const double fraction = std::stod(argv[3]);
    const size_t count = argc == 5 ? static_cast<size_t>(std::stoul(argv[4])) : files.size();
    std::filesystem::create_directories(argv[2]);
    for (size_t i = 0; i < files.size() && i < count; ++i) {
      const cv::Mat in = cv::imread(files[i], cv::IMREAD_UNCHANGED);
      if (in.empty()) throw std::runtime_error("cannot read " + files[i]);
      const int w = in.cols;
      const int shift = ((static_cast<int>(std::lround(fraction * w)) % w) + w) % w;
      cv::Mat out;  // a fresh buffer: hconcat into `in` itself would overwrite its source
      if (shift == 0) {
        out = in;
      } else {
        cv::hconcat(in.colRange(shift, w), in.colRange(0, shift), out);
      }
      const std::string path =
          (std::filesystem::path(argv[2]) / std::filesystem::path(files[i]).filename()).string();
      if (!cv::imwrite(path, out)) throw std::runtime_error("cannot write " + path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shift_panoramas: %s\n", e.what());
    return 1;
  }
  return 0;
}
