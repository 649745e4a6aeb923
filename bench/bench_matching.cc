// Matching kernels: N x N distance matrices (Hamming over 32-byte and 174-byte descriptors,
// L2 over 128 and 1764 floats), sequence sums for several L, and Eq. 5. Reported per pair of
// frames (items = pairs actually computed: one triangle for a symmetric matrix).
#include <benchmark/benchmark.h>
#include <immintrin.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "matching/distances.h"
#include "matching/matrix.h"
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

// The distance matrix of N random rows of `type` against themselves, by `distances` (Args:
// frames N, values per descriptor, threads). Items: pairs of the triangle.
using DistancesFunction = cv::Mat1f (*)(const cv::Mat&, const cv::Mat&, int,
                                        const openable::PairProgress&);
void TimeDistances(benchmark::State& state, int type, DistancesFunction distances) {
  const int n = static_cast<int>(state.range(0));
  const cv::Mat rows = RandomRows(n, static_cast<int>(state.range(1)), type);
  for (auto _ : state) {
    cv::Mat1f d = distances(rows, cv::Mat(), static_cast<int>(state.range(2)), {});
    benchmark::DoNotOptimize(d.data);
  }
  state.SetItemsProcessed(state.iterations() * TrianglePairs(n));
}

// Args: frames N, bytes per descriptor, threads.
void BM_Hamming(benchmark::State& state) {
  TimeDistances(state, CV_8U, openable::HammingDistances);
}
BENCHMARK(BM_Hamming)
    ->Args({3576, 32, 1})
    ->Args({3576, 32, 2})
    ->Args({3576, 174, 2})
    ->Args({10000, 32, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

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

// The bound of a 512-bit Hamming kernel on this CPU: 64-byte loads from an L1-resident buffer,
// each XOR-ed with a register, counted by VPOPCNTQ and accumulated in four independent chains,
// as many as the load ports and the VPOPCNTQ unit sustain. bits_per_second is the descriptor
// bits such a kernel could compare per second per core; pairs_per_second_256 the 256-bit pairs
// (LDB, ORB). The avx512 rows of BM_HammingKernel are measured against it. Skipped without
// AVX-512 VPOPCNTDQ.
__attribute__((target("avx512f,avx512vpopcntdq"), always_inline)) inline __m512i CountXor(
    __m512i sum, __m512i key, const std::uint64_t* words) {
  return _mm512_add_epi64(sum,
                          _mm512_popcnt_epi64(_mm512_xor_si512(key, _mm512_loadu_si512(words))));
}

__attribute__((target("avx512f,avx512vpopcntdq"))) std::uint64_t PopcountLoadsAvx512(
    const std::uint64_t* data, int vectors, int rounds) {
  const __m512i key = _mm512_set1_epi64(0x0123456789abcdefLL);
  __m512i a0 = _mm512_setzero_si512(), a1 = a0, a2 = a0, a3 = a0;
  for (int r = 0; r < rounds; ++r)
    for (int v = 0; v < vectors; v += 4) {
      a0 = CountXor(a0, key, data + 8 * v);
      a1 = CountXor(a1, key, data + 8 * v + 8);
      a2 = CountXor(a2, key, data + 8 * v + 16);
      a3 = CountXor(a3, key, data + 8 * v + 24);
      // Keeps the compiler from folding the rounds (the same data gives the same counts).
      asm volatile("" : "+v"(a0), "+v"(a1), "+v"(a2), "+v"(a3));
    }
  alignas(64) std::uint64_t lanes[8];
  _mm512_store_si512(lanes, _mm512_add_epi64(_mm512_add_epi64(a0, a1), _mm512_add_epi64(a2, a3)));
  std::uint64_t total = 0;
  for (const std::uint64_t lane : lanes) total += lane;
  return total;
}

void BM_Avx512PopcountBound(benchmark::State& state) {
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx512f") || !__builtin_cpu_supports("avx512vpopcntdq")) {
    state.SkipWithError("this CPU lacks AVX-512 VPOPCNTDQ");
    return;
  }
  constexpr int kVectors = 256;  // 16 KB: stays in L1
  constexpr int kRounds = 256;
  std::vector<std::uint64_t> data(8 * kVectors);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = 0x9e3779b97f4a7c15ULL * (i + 1);
  std::uint64_t sink = 0;
  for (auto _ : state) sink += PopcountLoadsAvx512(data.data(), kVectors, kRounds);
  benchmark::DoNotOptimize(sink);
  const double bits = static_cast<double>(state.iterations()) * kRounds * kVectors * 512;
  state.counters["bits_per_second"] = benchmark::Counter(bits, benchmark::Counter::kIsRate);
  state.counters["pairs_per_second_256"] =
      benchmark::Counter(bits / 256, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Avx512PopcountBound);

// The Hamming kernel alone on one core: one query against N references into a reused row
// (no allocation, no threads), for each kernel the CPU has. Args: references, bytes, kernel
// (0 auto, 1 portable, 2 popcnt, 3 avx2, 4 avx512). bits_per_second counts descriptor bits
// compared, comparable with BM_PopcntInstruction's and BM_Avx512PopcountBound's.
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
    ->Args({2048, 32, 1})
    ->Args({2048, 32, 2})
    ->Args({2048, 32, 3})
    ->Args({2048, 32, 4})
    ->Args({2048, 174, 1})
    ->Args({2048, 174, 2})
    ->Args({2048, 174, 3})
    ->Args({2048, 174, 4});

// Args: frames N, floats per descriptor, threads.
void BM_L2(benchmark::State& state) { TimeDistances(state, CV_32F, openable::L2Distances); }
BENCHMARK(BM_L2)
    ->Args({3576, 128, 2})
    ->Args({3576, 1764, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

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
BENCHMARK(BM_Sequence)
    ->Args({3576, 1})
    ->Args({3576, 10})
    ->Args({3576, 100})
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

// The dense matrix of a run of two traversals of 1788 frames (as Nordland's) with LDB rows
// (32 bytes), L = 10, forward, Sequence_partial ahead, before Eq. 5's scaling: in two passes
// (every distance, then the sequence sums; Args 0) or in one (FusedSequenceMatrix; Args 1).
// Items: matrix cells, to hold against the kernel's pairs per second (BM_HammingKernel).
void BM_DenseSequenceMatrix(benchmark::State& state) {
  const int n = 3576, L = 10;
  const cv::Mat rows = RandomRows(n, 32, CV_8U);
  const std::vector<int> starts = {0, n / 2};
  for (auto _ : state) {
    cv::Mat1f m;
    if (state.range(0) == 0) {
      m = openable::HammingDistances(rows, cv::Mat(), 2);
      openable::SequenceDistancesInPlace(m, L, starts, starts,
                                         openable::SequenceDirection::kForward, 2);
      benchmark::DoNotOptimize(openable::LargestFiniteEntry(m));
    } else {
      float largest = 0.0f;
      m = openable::FusedSequenceMatrix(rows, openable::Metric::kHamming, L,
                                        openable::SequenceDirection::kForward,
                                        openable::SequencePartial::kAhead, starts, 2, largest);
      benchmark::DoNotOptimize(largest);
    }
    benchmark::DoNotOptimize(m.data);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n) * n);
  state.SetLabel(state.range(0) == 0 ? "two passes" : "one pass");
}
BENCHMARK(BM_DenseSequenceMatrix)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
