// Writes copies of colour images as a camera would have seen them under another light: the
// illuminant moved along the black-body locus from temperature T1 to T2 (Wien's approximation)
// and its intensity scaled by k. Channel c (peak response lambda_c) is multiplied by
//   k * exp(-(c2 / lambda_c) (1/T2 - 1/T1)) / exp(-(c2 / lambda_G) (1/T2 - 1/T1)),
// c2 = 1.4388e-2 m K (normalised so that green is scaled by exactly k),
// the change Eq. 6 of the OpenABLE paper cancels (Maddern et al. 2014) when alpha comes from the
// same peak responses by Eq. 7 (then log gG - alpha log gB - (1 - alpha) log gR = 0 for these
// gains), before the result is saturated to 8 bits. Used by bench/illumination.sh.
// Usage: relight <input folder> <output folder> <T1 K> <T2 K> <k> [red green blue nm]
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "OpenABLE/io/frame_source.h"

int main(int argc, char** argv) {
  if (argc != 6 && argc != 9) {
    std::fprintf(stderr, "usage: relight <input> <output> <T1 K> <T2 K> <k> [red green blue nm]\n");
    return 2;
  }
  try {
    const double t1 = std::stod(argv[3]), t2 = std::stod(argv[4]), k = std::stod(argv[5]);
    double nm[3] = {470, 535, 610};  // B, G, R: KITTI's PointGrey Flea2 (OpenABLE paper)
    if (argc == 9)
      nm[2] = std::stod(argv[6]), nm[1] = std::stod(argv[7]), nm[0] = std::stod(argv[8]);
    const double c2 = 1.4388e-2;
    cv::Scalar gain;
    for (int c = 0; c < 3; ++c)
      gain[c] = k * std::exp(-(c2 / (nm[c] * 1e-9) - c2 / (nm[1] * 1e-9)) * (1.0 / t2 - 1.0 / t1));
    std::printf("relight: gains B %.3f G %.3f R %.3f\n", gain[0], gain[1], gain[2]);
    std::filesystem::create_directories(argv[2]);
    for (const std::string& file : openable::ListImages(argv[1], "")) {
      const cv::Mat in = cv::imread(file, cv::IMREAD_COLOR);
      if (in.empty()) throw std::runtime_error("cannot read " + file);
      cv::Mat f, out;
      in.convertTo(f, CV_32FC3);
      cv::multiply(f, gain, f);
      f.convertTo(out, CV_8UC3);  // rounded and saturated, as a camera would clip
      const std::string path =
          (std::filesystem::path(argv[2]) / std::filesystem::path(file).filename()).string();
      if (!cv::imwrite(path, out)) throw std::runtime_error("cannot write " + path);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "relight: %s\n", e.what());
    return 1;
  }
  return 0;
}
