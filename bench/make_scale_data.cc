// Writes the frames of the end-to-end scale benchmark (bench/scale.sh): N reference and N
// query frames made from the real Nordland trimmed frames (summer for references, winter for
// queries), repeated and perturbed so that no two frames are equal: repetition r of a frame is
// shifted by up to 2 pixels and given Gaussian noise (sigma 4 grey levels), seeded by its
// number. Usage: make_scale_data <nordland_trimmed folder> <output folder> <N>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr,
                 "usage: make_scale_data <nordland_trimmed> <output> <frames per traversal>\n");
    return 2;
  }
  const fs::path in = argv[1], out = argv[2];
  const int n = std::stoi(argv[3]);
  for (const char* season : {"summer", "winter"}) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(in / season)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) {
      std::fprintf(stderr, "make_scale_data: no frames in %s\n", (in / season).c_str());
      return 1;
    }
    std::vector<cv::Mat> frames;
    for (const auto& f : files) frames.push_back(cv::imread(f.string(), cv::IMREAD_GRAYSCALE));
    const fs::path dir = out / season;
    fs::create_directories(dir);
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& r) {
      for (int i = r.start; i < r.end; ++i) {
        const cv::Mat& src = frames[static_cast<size_t>(i) % frames.size()];
        const int rep = i / static_cast<int>(frames.size());
        cv::Mat frame = src;
        if (rep > 0) {
          cv::RNG rng(static_cast<std::uint64_t>(i) * 2654435761u + 17);
          const cv::Mat shift =
              (cv::Mat_<double>(2, 3) << 1, 0, rng.uniform(-2, 3), 0, 1, rng.uniform(-2, 3));
          cv::warpAffine(src, frame, shift, src.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
          cv::Mat noise(frame.size(), CV_16S);
          rng.fill(noise, cv::RNG::NORMAL, 0, 4);
          cv::Mat sum;
          frame.convertTo(sum, CV_16S);
          sum += noise;
          sum.convertTo(frame, CV_8U);
        }
        char name[32];
        std::snprintf(name, sizeof name, "%07d.png", i);
        cv::imwrite((dir / name).string(), frame);
      }
    });
  }
  return 0;
}
