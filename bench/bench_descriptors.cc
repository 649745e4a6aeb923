// Time to describe one 64 x 64 patch with each registered descriptor (global description, one
// thread). Input: a fixed pseudo-random textured patch (the cost does not depend on content).
// DenseVLAD, which takes a whole frame: one 960 x 540 textured frame (a Gardens Point frame's
// size), and the learning of its vocabulary from 40 such frames. Run with
// OPENCV_FOR_THREADS_NUM=1 for one thread (OpenCV's SIFT and k-means use its threads).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "descriptors/registry.h"

namespace {

cv::Mat TexturedPatch(int side) {
  cv::Mat noise(side, side, CV_8UC1);
  cv::RNG rng(12345);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, noise, cv::Size(5, 5), 1.5);
  return noise;
}

void BM_Describe(benchmark::State& state, const std::string& name, int ldb_bits) {
  openable::DescriptorOptions options;
  options.patch_size = static_cast<int>(state.range(0));
  options.ldb_bits = ldb_bits;
  const std::unique_ptr<openable::Descriptor> d = openable::CreateDescriptor(name, options);
  const cv::Mat patch = TexturedPatch(options.patch_size);
  cv::Mat row(1, d->Width(), openable::RowType(*d));
  for (auto _ : state) {
    d->Describe(patch, row);
    benchmark::DoNotOptimize(row.data);
  }
  state.SetItemsProcessed(state.iterations());
}

// A frame of `size` textured at several scales (blurred noise of three widths summed).
cv::Mat TexturedFrame(cv::Size size, int seed) {
  cv::Mat1f sum = cv::Mat1f::zeros(size);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  for (const double sigma : {1.5, 4.0, 12.0}) {
    cv::Mat1f noise(size);
    rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::GaussianBlur(noise, noise, cv::Size(), sigma);
    cv::normalize(noise, noise, 0, 85, cv::NORM_MINMAX);
    sum += noise;
  }
  cv::Mat out;
  sum.convertTo(out, CV_8U);
  return out;
}

void BM_DenseVladDescribe(benchmark::State& state) {
  openable::DescriptorOptions options;
  const auto d = openable::CreateDescriptor("DenseVLAD", options);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 8; ++i) frames.push_back(TexturedFrame(cv::Size(960, 540), i));
  d->Learn(frames);
  cv::Mat row(1, d->Width(), CV_32F);
  for (auto _ : state) {
    d->Describe(frames[3], row);
    benchmark::DoNotOptimize(row.data);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_DenseVladLearn40(benchmark::State& state) {
  openable::DescriptorOptions options;
  std::vector<cv::Mat> frames;
  for (int i = 0; i < 40; ++i) frames.push_back(TexturedFrame(cv::Size(960, 540), i));
  for (auto _ : state) {
    const auto d = openable::CreateDescriptor("DenseVLAD", options);
    d->Learn(frames);
    benchmark::DoNotOptimize(d->Fingerprint().data());
  }
}

}  // namespace

BENCHMARK_CAPTURE(BM_Describe, LDB_256, std::string("LDB"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, LDB_1386, std::string("LDB"), 1386)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, ORB, std::string("ORB"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, BRISK, std::string("BRISK"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, SIFT, std::string("SIFT"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, HOG, std::string("HOG"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, BRIEF, std::string("BRIEF"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, FREAK, std::string("FREAK"), 256)->Arg(64);

BENCHMARK(BM_DenseVladDescribe)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DenseVladLearn40)->Unit(benchmark::kMillisecond)->Iterations(2);

BENCHMARK_MAIN();
