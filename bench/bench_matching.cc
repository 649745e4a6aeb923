// Matching kernels: N x N distance matrices (Hamming over 32-byte and 174-byte descriptors,
// L2 over 128 and 1764 floats), sequence sums for several L, and Eq. 5. Reported per pair of
// frames (items = pairs actually computed: one triangle for a symmetric matrix).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

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

// The popcount instruction's peak throughput on this CPU: blocks of sixteen POPCNT over four
// registers with no dependency between them and no memory traffic, reported as bits counted
// per second. The reference for the Hamming kernel's bits_per_second below.
void BM_PopcntInstruction(benchmark::State& state) {
  std::uint64_t a = 0x0123456789abcdefULL, b = ~a, c = a * 3, d = a * 5;
  std::uint64_t o[8];
  std::uint64_t sink = 0;
  constexpr int kRounds = 1 << 16;
  for (auto _ : state) {
    for (int r = 0; r < kRounds; ++r) {
      asm volatile(
          "popcnt %8, %0\n\tpopcnt %9, %1\n\tpopcnt %10, %2\n\tpopcnt %11, %3\n\t"
          "popcnt %8, %4\n\tpopcnt %9, %5\n\tpopcnt %10, %6\n\tpopcnt %11, %7\n\t"
          "popcnt %8, %0\n\tpopcnt %9, %1\n\tpopcnt %10, %2\n\tpopcnt %11, %3\n\t"
          "popcnt %8, %4\n\tpopcnt %9, %5\n\tpopcnt %10, %6\n\tpopcnt %11, %7"
          : "=r"(o[0]), "=r"(o[1]), "=r"(o[2]), "=r"(o[3]), "=r"(o[4]), "=r"(o[5]), "=r"(o[6]),
            "=r"(o[7])
          : "r"(a), "r"(b), "r"(c), "r"(d));
    }
    sink += o[0] ^ o[7];
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations() * kRounds * 16);  // instructions
  state.counters["bits_per_second"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * kRounds * 16 * 64, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PopcntInstruction);

// The Hamming kernel alone on one core: one query against N references into a reused row
// (no allocation, no threads), for each kernel the CPU has. Args: references, bytes, kernel
// (0 auto, 1 portable, 2 popcnt, 3 avx2). bits_per_second counts descriptor bits compared,
// comparable with BM_PopcntInstruction's.
void BM_HammingKernel(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int bytes = static_cast<int>(state.range(1));
  const auto kernel = static_cast<openable::HammingKernel>(state.range(2));
  if (!openable::ForceHammingKernel(kernel)) {
    state.SkipWithError("this CPU lacks the kernel");
    return;
  }
  state.SetLabel(openable::HammingKernelName());
  const cv::Mat refs = RandomRows(n, bytes, CV_8U);
  const cv::Mat queries = RandomRows(64, bytes, CV_8U);
  const openable::HammingReferences packed(refs);
  std::vector<float> out(static_cast<size_t>(n));
  int q = 0;
  for (auto _ : state) {
    packed.Distances(queries.ptr<std::uint8_t>(q), out.data());
    q = (q + 1) % queries.rows;
    benchmark::DoNotOptimize(out.data());
  }
  openable::ForceHammingKernel(openable::HammingKernel::kAuto);
  state.SetItemsProcessed(state.iterations() * n);  // pairs
  state.counters["bits_per_second"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * n * bytes * 8, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HammingKernel)
    ->Args({2048, 32, 1})->Args({2048, 32, 2})->Args({2048, 32, 3})
    ->Args({2048, 174, 1})->Args({2048, 174, 2})->Args({2048, 174, 3});

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
