// Time to describe one 64 x 64 patch with each registered descriptor (global description, one
// thread). Input: a fixed pseudo-random textured patch (the cost does not depend on content).
#include <benchmark/benchmark.h>

#include <memory>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

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

}  // namespace

BENCHMARK_CAPTURE(BM_Describe, LDB_256, std::string("LDB"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, LDB_1386, std::string("LDB"), 1386)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, ORB, std::string("ORB"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, BRISK, std::string("BRISK"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, SIFT, std::string("SIFT"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, HOG, std::string("HOG"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, BRIEF, std::string("BRIEF"), 256)->Arg(64);
BENCHMARK_CAPTURE(BM_Describe, FREAK, std::string("FREAK"), 256)->Arg(64);

BENCHMARK_MAIN();
