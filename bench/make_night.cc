// Writes night-like copies of day frames (openable::MakeNightLike, OpenABLE/image/robustness.h):
// another viewpoint by a few per cent, light from one side, a dark sky, a low-light tone curve,
// a sodium-like cast, the camera's gain with its noise, and glare. Synthetic: the shared
// datasets have no night traversal, and docs/benchmarks.md says which figures come from these.
// Usage: make_night <input folder> <output folder> [--strong] [--from-left] [--seed N]
//                   [--zoom Z] [--shift S] [--rotation DEG] [--noise K]
// (--strong first; --zoom, --shift and --rotation replace the viewpoint change, --noise
// multiplies the noise's deviations.)
// Every image of the input folder (natural order) is written under the same file name; frame i
// takes the noise and viewpoint of NoiseState(seed, 7, i), so a run is repeatable.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/image/robustness.h"
#include "OpenABLE/io/frame_source.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  openable::NightOptions options;
  int seed = 0;
  std::vector<std::string> folders;
  try {
    for (size_t i = 0; i < args.size(); ++i) {
      if (args[i] == "--strong") {
        const bool left = options.from_left;
        options = openable::NightOptions::Strong();
        options.from_left = left;
      } else if (args[i] == "--from-left") {
        options.from_left = true;
      } else if (args[i] == "--seed" && i + 1 < args.size()) {
        seed = std::stoi(args[++i]);
      } else if (args[i] == "--zoom" && i + 1 < args.size()) {
        options.zoom = std::stod(args[++i]);
      } else if (args[i] == "--shift" && i + 1 < args.size()) {
        options.shift = std::stod(args[++i]);
      } else if (args[i] == "--rotation" && i + 1 < args.size()) {
        options.rotation = std::stod(args[++i]);
      } else if (args[i] == "--noise" && i + 1 < args.size()) {
        const double k = std::stod(args[++i]);
        options.shot *= k;
        options.read *= k;
      } else {
        folders.push_back(args[i]);
      }
    }
    if (folders.size() != 2) {
      std::fprintf(stderr,
                   "usage: make_night <input folder> <output folder> [--strong] "
                   "[--from-left] [--seed N] [--zoom Z] [--shift S] [--rotation DEG] "
                   "[--noise K]\n");
      return 2;
    }
    std::filesystem::create_directories(folders[1]);
    int frame = 0;
    for (const std::string& file : openable::ListImages(folders[0], "")) {
      const cv::Mat in = cv::imread(file, cv::IMREAD_COLOR);
      if (in.empty()) throw std::runtime_error("cannot read " + file);
      cv::Mat f, out;
      in.convertTo(f, CV_32FC3, 1.0 / 255.0);
      const cv::Mat night =
          openable::MakeNightLike(f, options, openable::NoiseState(seed, 7, frame++));
      night.convertTo(out, CV_8UC3, 255.0);
      const std::string path =
          (std::filesystem::path(folders[1]) / std::filesystem::path(file).filename()).string();
      if (!cv::imwrite(path, out)) throw std::runtime_error("cannot write " + path);
    }
    std::printf("make_night: %d frames written to %s\n", frame, folders[1].c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_night: %s\n", e.what());
    return 1;
  }
  return 0;
}
