// Matching kernels: N x N distance matrices (Hamming over 32-byte and 174-byte descriptors,
// L2 over 128 and 1764 floats), sequence sums for several L, and Eq. 5. Reported per pair of
// frames (items = pairs actually computed: one triangle for a symmetric matrix).
#include <benchmark/benchmark.h>

#include <cstdint>

#include <opencv2/core.hpp>

#include "matching/distances.h"
#include "matching/normalize.h"
#include "matching/sequence.h"

namespace {

cv::Mat RandomRows(int n, int width, int type) {
  cv::Mat m(n, width, type);
  cv::RNG rng(7);
  if (type == CV_8U)
    rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  else
    rng.fill(m, cv::RNG::UNIFORM, 0.0, 1.0);
  return m;
}

std::int64_t TrianglePairs(std::int64_t n) { return n * (n - 1) / 2; }

// Args: frames N, bytes per descriptor, threads.
void BM_Hamming(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const cv::Mat rows = RandomRows(n, static_cast<int>(state.range(1)), CV_8U);
  for (auto _ : state) {
    cv::Mat1f d = openable::HammingDistances(rows, cv::Mat(), static_cast<int>(state.range(2)));
    benchmark::DoNotOptimize(d.data);
  }
  state.SetItemsProcessed(state.iterations() * TrianglePairs(n));
}
BENCHMARK(BM_Hamming)
    ->Args({3576, 32, 1})->Args({3576, 32, 2})->Args({3576, 174, 2})->Args({10000, 32, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Args: frames N, floats per descriptor, threads.
void BM_L2(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const cv::Mat rows = RandomRows(n, static_cast<int>(state.range(1)), CV_32F);
  for (auto _ : state) {
    cv::Mat1f d = openable::L2Distances(rows, cv::Mat(), static_cast<int>(state.range(2)));
    benchmark::DoNotOptimize(d.data);
  }
  state.SetItemsProcessed(state.iterations() * TrianglePairs(n));
}
BENCHMARK(BM_L2)
    ->Args({3576, 128, 2})->Args({3576, 1764, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Args: frames N, sequence length L. Items: matrix cells.
void BM_Sequence(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const cv::Mat1f d = RandomRows(n, n, CV_32F);
  const std::vector<int> starts = {0, n / 2};
  for (auto _ : state) {
    cv::Mat1f s = openable::SequenceDistances(d, static_cast<int>(state.range(1)), starts, starts);
    benchmark::DoNotOptimize(s.data);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n) * n);
}
BENCHMARK(BM_Sequence)->Args({3576, 1})->Args({3576, 10})->Args({3576, 100})
    ->Unit(benchmark::kMillisecond);

void BM_NormalizeByMax(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const cv::Mat1f d = RandomRows(n, n, CV_32F);
  for (auto _ : state) {
    cv::Mat1f m = d.clone();
    benchmark::DoNotOptimize(openable::NormalizeByMax(m));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n) * n);
}
BENCHMARK(BM_NormalizeByMax)->Arg(3576)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
