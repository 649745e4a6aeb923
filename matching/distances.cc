#include "matching/distances.h"

#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "OpenABLE/base/threading.h"
#include "matching/blas.h"
#include "matching/large_matrix.h"

namespace openable {
namespace {

// Descriptor rows as 64-bit words (zero-padded) in blocks of 4 references, word-major inside a
// block: block b holds word k of references 4b..4b+3 at [b][k][0..3]. The AVX2 kernel loads
// word k of four references in one register; the scalar kernels read the same layout.
// `base` is `data`, or words held elsewhere (HammingReferences over packed words in place, a
// mapped map file): the kernels read `base` only.
struct PackedRows {
  int words = 0;
  int rows = 0;
  int blocks = 0;
  std::vector<std::uint64_t> data;
  const std::uint64_t* base = nullptr;
  const std::uint64_t* Block(int b) const { return base + static_cast<size_t>(b) * words * 4; }
};

PackedRows Pack(const cv::Mat& m) {
  PackedRows p;
  p.rows = m.rows;
  p.words = (m.cols + 7) / 8;
  p.blocks = (m.rows + 3) / 4;
  p.data.assign(static_cast<size_t>(p.blocks) * p.words * 4, 0);
  std::vector<std::uint64_t> row(static_cast<size_t>(p.words));
  for (int i = 0; i < m.rows; ++i) {
    std::fill(row.begin(), row.end(), 0);
    std::memcpy(row.data(), m.ptr<std::uint8_t>(i), m.cols);
    for (int k = 0; k < p.words; ++k)
      p.data[(static_cast<size_t>(i / 4) * p.words + k) * 4 + i % 4] = row[k];
  }
  p.base = p.data.data();
  return p;
}

// One query (`words` words) against references [4 * b0, 4 * b1), written to out[0 ...] (out[i]:
// reference 4 * b0 + i)
// (only rows < refs.rows are written).
using Kernel = void (*)(const std::uint64_t* q, const PackedRows& refs, int b0, int b1, float* out);

// Portable kernel and the POPCNT one: the same loop, compiled twice. The standard library has
// no popcount before C++20; GCC's builtin becomes the instruction in a function compiled for
// POPCNT and a bit trick elsewhere.
inline __attribute__((always_inline)) void ScalarBlocks(const std::uint64_t* q,
                                                        const PackedRows& refs, int b0, int b1,
                                                        float* out) {
  const int words = refs.words;
  for (int b = b0; b < b1; ++b) {
    const std::uint64_t* block = refs.Block(b);
    int bits[4] = {0, 0, 0, 0};
    for (int k = 0; k < words; ++k)
      for (int lane = 0; lane < 4; ++lane)
        bits[lane] += __builtin_popcountll(q[k] ^ block[4 * k + lane]);
    const int valid = std::min(4, refs.rows - 4 * b);
    for (int lane = 0; lane < valid; ++lane)
      out[4 * (b - b0) + lane] = static_cast<float>(bits[lane]);
  }
}

void PortableKernel(const std::uint64_t* q, const PackedRows& refs, int b0, int b1, float* out) {
  ScalarBlocks(q, refs, b0, b1, out);
}

__attribute__((target("popcnt"))) void PopcntKernel(const std::uint64_t* q, const PackedRows& refs,
                                                    int b0, int b1, float* out) {
  ScalarBlocks(q, refs, b0, b1, out);
}

// AVX2 has no 64-bit popcount instruction: each XOR-ed register is counted per byte with the
// nibble table of Mula's method (two PSHUFB lookups), byte counts are added for up to 31 words
// (8 per byte per word, so no byte overflows), then summed per 64-bit lane by PSADBW. The four
// lanes are the four references of a block. Written by hand: no library among our dependencies
// offers a batched Hamming kernel over this layout.
struct Avx2Consts {
  __m256i table, low, zero, pick;
};

__attribute__((target("avx2"), always_inline)) inline Avx2Consts MakeAvx2Consts() {
  return {_mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4,  //
                           0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4),
          _mm256_set1_epi8(0x0f), _mm256_setzero_si256(),
          _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)};
}

// Byte counts of (q ^ four references) added to `bytes`.
__attribute__((target("avx2"), always_inline)) inline __m256i AddCounts(const Avx2Consts& c,
                                                                        __m256i bytes, __m256i qk,
                                                                        const std::uint64_t* refs) {
  const __m256i x =
      _mm256_xor_si256(qk, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(refs)));
  const __m256i lo = _mm256_shuffle_epi8(c.table, _mm256_and_si256(x, c.low));
  const __m256i hi = _mm256_shuffle_epi8(c.table, _mm256_and_si256(_mm256_srli_epi16(x, 4), c.low));
  return _mm256_add_epi8(bytes, _mm256_add_epi8(lo, hi));
}

// Stores the counts of two blocks (8 references), `valid` of them.
__attribute__((target("avx2"), always_inline)) inline void StoreCounts(const Avx2Consts& c,
                                                                       __m256i t0, __m256i t1,
                                                                       int valid, float* out) {
  // Counts fit in 32 bits: keep the low half of each 64-bit lane, convert, store 8 floats.
  const __m256i packed = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(t0, c.pick),
                                            _mm256_permutevar8x32_epi32(t1, c.pick), 0xf0);
  const __m256 counts = _mm256_cvtepi32_ps(packed);
  if (valid == 8) {
    _mm256_storeu_ps(out, counts);
  } else {
    alignas(32) float tmp[8];
    _mm256_store_ps(tmp, counts);
    std::copy(tmp, tmp + valid, out);
  }
}

// W words known at compile time (W <= 31): the broadcast query stays in registers and the
// word loop unrolls. Two blocks per step for instruction-level parallelism.
template <int W>
__attribute__((target("avx2,popcnt"))) void Avx2FixedKernel(const std::uint64_t* q,
                                                            const PackedRows& refs, int b0, int b1,
                                                            float* out) {
  static_assert(W >= 1 && W <= 31, "byte counters hold 31 words");
  const Avx2Consts c = MakeAvx2Consts();
  __m256i qk[W];
  for (int k = 0; k < W; ++k) qk[k] = _mm256_set1_epi64x(static_cast<long long>(q[k]));
  int b = b0;
  // Groups of three blocks: two counted in the vector unit, the third by POPCNT in the integer
  // unit at the same time. Each alone leaves the other unit idle; together they count about a
  // third more bits per cycle (bench_matching, BM_HammingKernel).
  for (; b + 4 < b1; b += 5) {
    const std::uint64_t* block0 = refs.Block(b);
    const std::uint64_t* block4 = block0 + 16 * W;
    __m256i bytes0 = c.zero, bytes1 = c.zero, bytes2 = c.zero, bytes3 = c.zero;
    std::uint64_t s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    for (int k = 0; k < W; ++k) {
      bytes0 = AddCounts(c, bytes0, qk[k], block0 + 4 * k);
      bytes1 = AddCounts(c, bytes1, qk[k], block0 + 4 * W + 4 * k);
      bytes2 = AddCounts(c, bytes2, qk[k], block0 + 8 * W + 4 * k);
      bytes3 = AddCounts(c, bytes3, qk[k], block0 + 12 * W + 4 * k);
      s0 += static_cast<std::uint64_t>(__builtin_popcountll(q[k] ^ block4[4 * k]));
      s1 += static_cast<std::uint64_t>(__builtin_popcountll(q[k] ^ block4[4 * k + 1]));
      s2 += static_cast<std::uint64_t>(__builtin_popcountll(q[k] ^ block4[4 * k + 2]));
      s3 += static_cast<std::uint64_t>(__builtin_popcountll(q[k] ^ block4[4 * k + 3]));
    }
    StoreCounts(c, _mm256_sad_epu8(bytes0, c.zero), _mm256_sad_epu8(bytes1, c.zero), 8,
                out + 4 * (b - b0));
    StoreCounts(c, _mm256_sad_epu8(bytes2, c.zero), _mm256_sad_epu8(bytes3, c.zero), 8,
                out + 4 * (b - b0) + 8);
    const int valid = std::min(4, refs.rows - 4 * (b + 4));
    const float counts[4] = {static_cast<float>(s0), static_cast<float>(s1), static_cast<float>(s2),
                             static_cast<float>(s3)};
    std::copy(counts, counts + valid, out + 4 * (b + 4 - b0));
  }
  for (; b + 1 < b1; b += 2) {
    const std::uint64_t* block0 = refs.Block(b);
    const std::uint64_t* block1 = block0 + 4 * W;
    __m256i bytes0 = c.zero, bytes1 = c.zero;
    for (int k = 0; k < W; ++k) {
      bytes0 = AddCounts(c, bytes0, qk[k], block0 + 4 * k);
      bytes1 = AddCounts(c, bytes1, qk[k], block1 + 4 * k);
    }
    StoreCounts(c, _mm256_sad_epu8(bytes0, c.zero), _mm256_sad_epu8(bytes1, c.zero),
                std::min(8, refs.rows - 4 * b), out + 4 * (b - b0));
  }
  if (b < b1) PopcntKernel(q, refs, b, b1, out + 4 * (b - b0));  // an odd last block
}

__attribute__((target("avx2,popcnt"))) void Avx2Kernel(const std::uint64_t* q,
                                                       const PackedRows& refs, int b0, int b1,
                                                       float* out) {
  switch (refs.words) {
    case 4:
      return Avx2FixedKernel<4>(q, refs, b0, b1, out);  // 256 bits (LDB, ORB)
    case 8:
      return Avx2FixedKernel<8>(q, refs, b0, b1, out);  // 512 bits (BRISK)
    case 22:
      return Avx2FixedKernel<22>(q, refs, b0, b1, out);  // 1386 bits (all LDB tests)
    default:
      break;
  }
  const Avx2Consts c = MakeAvx2Consts();
  const int words = refs.words;
  int b = b0;
  for (; b + 1 < b1; b += 2) {
    const std::uint64_t* block0 = refs.Block(b);
    const std::uint64_t* block1 = refs.Block(b + 1);
    __m256i total0 = c.zero, total1 = c.zero;
    for (int k0 = 0; k0 < words; k0 += 31) {
      const int k1 = std::min(words, k0 + 31);
      __m256i bytes0 = c.zero, bytes1 = c.zero;
      for (int k = k0; k < k1; ++k) {
        const __m256i qk = _mm256_set1_epi64x(static_cast<long long>(q[k]));
        bytes0 = AddCounts(c, bytes0, qk, block0 + 4 * k);
        bytes1 = AddCounts(c, bytes1, qk, block1 + 4 * k);
      }
      total0 = _mm256_add_epi64(total0, _mm256_sad_epu8(bytes0, c.zero));
      total1 = _mm256_add_epi64(total1, _mm256_sad_epu8(bytes1, c.zero));
    }
    StoreCounts(c, total0, total1, std::min(8, refs.rows - 4 * b), out + 4 * (b - b0));
  }
  if (b < b1) PopcntKernel(q, refs, b, b1, out + 4 * (b - b0));  // an odd last block
}

// AVX-512 with VPOPCNTQ (Ice Lake, Zen 4 and later): one 512-bit load holds words k and k+1
// of a block's four references ([b][k][0..3], [b][k+1][0..3]); XOR with (q[k] x 4, q[k+1] x 4)
// and VPOPCNTQ count 8 words at once, accumulated in 64-bit lanes. Lanes i and i + 4 belong to
// reference i: two blocks are folded together and converted to 8 floats at the end. Written
// by hand because OpenCV's Hamming norm (cv::batchDistance) works on one pair of rows at a
// time in this layout's stead and does not use VPOPCNTQ. Four blocks per step keep four
// independent accumulator chains in flight.
#define OPENABLE_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx512vpopcntdq,popcnt")))

OPENABLE_AVX512 __attribute__((always_inline)) inline __m512i QueryPair(const std::uint64_t* q,
                                                                        int k, int words) {
  const long long hi = k + 1 < words ? static_cast<long long>(q[k + 1]) : 0;
  return _mm512_mask_set1_epi64(_mm512_set1_epi64(static_cast<long long>(q[k])), 0xF0, hi);
}

// Words k, k + 1 of a block (only word k, upper half zero, when k is the last word).
OPENABLE_AVX512 __attribute__((always_inline)) inline __m512i BlockPair(const std::uint64_t* block,
                                                                        int k, int words) {
  return k + 1 < words ? _mm512_loadu_si512(block + 4 * k)
                       : _mm512_maskz_loadu_epi64(0x0F, block + 4 * k);
}

// out[0 ...]: the counts of blocks b (acc0) and b + 1 (acc1), `valid` of the 8 floats.
OPENABLE_AVX512 __attribute__((always_inline)) inline void StorePair(__m512i acc0, __m512i acc1,
                                                                     int valid, float* out) {
  const __m512i lo_lanes = _mm512_setr_epi64(0, 1, 2, 3, 8, 9, 10, 11);
  const __m512i hi_lanes = _mm512_setr_epi64(4, 5, 6, 7, 12, 13, 14, 15);
  const __m512i sum = _mm512_add_epi64(_mm512_permutex2var_epi64(acc0, lo_lanes, acc1),
                                       _mm512_permutex2var_epi64(acc0, hi_lanes, acc1));
  _mm256_mask_storeu_ps(out, static_cast<__mmask8>((1u << valid) - 1), _mm512_cvtepi64_ps(sum));
}

// sum + the bits of words k, k + 1 of `block` that differ from the query's (qv).
OPENABLE_AVX512 __attribute__((always_inline)) inline __m512i AddPairCount(
    __m512i sum, __m512i qv, const std::uint64_t* block, int k, int words) {
  return _mm512_add_epi64(sum,
                          _mm512_popcnt_epi64(_mm512_xor_si512(qv, BlockPair(block, k, words))));
}

template <int Pairs>  // word pairs per row; 0: any (read from refs.words)
OPENABLE_AVX512 void Avx512Blocks(const std::uint64_t* q, const PackedRows& refs, int b0, int b1,
                                  float* out) {
  const int words = refs.words;
  const int pairs = Pairs > 0 ? Pairs : (words + 1) / 2;
  constexpr int kKept = Pairs > 0 ? Pairs : 1;
  __m512i qk[kKept];
  if (Pairs > 0)
    for (int p = 0; p < Pairs; ++p) qk[p] = QueryPair(q, 2 * p, words);
  const __m512i zero = _mm512_setzero_si512();
  int b = b0;
  for (; b + 3 < b1; b += 4) {
    const std::uint64_t* block = refs.Block(b);
    const std::size_t stride = static_cast<std::size_t>(4) * words;
    __m512i a0 = zero, a1 = zero, a2 = zero, a3 = zero;
    for (int p = 0; p < pairs; ++p) {
      const int k = 2 * p;
      const __m512i qv = Pairs > 0 ? qk[p] : QueryPair(q, k, words);
      a0 = AddPairCount(a0, qv, block, k, words);
      a1 = AddPairCount(a1, qv, block + stride, k, words);
      a2 = AddPairCount(a2, qv, block + 2 * stride, k, words);
      a3 = AddPairCount(a3, qv, block + 3 * stride, k, words);
    }
    StorePair(a0, a1, std::min(8, refs.rows - 4 * b), out + 4 * (b - b0));
    StorePair(a2, a3, std::max(0, std::min(8, refs.rows - 4 * (b + 2))), out + 4 * (b - b0) + 8);
  }
  for (; b < b1; b += 2) {  // the last one to three blocks, two at a time
    const std::uint64_t* block = refs.Block(b);
    const bool two = b + 1 < b1;
    __m512i a0 = zero, a1 = zero;
    for (int p = 0; p < pairs; ++p) {
      const int k = 2 * p;
      const __m512i qv = Pairs > 0 ? qk[p] : QueryPair(q, k, words);
      a0 = AddPairCount(a0, qv, block, k, words);
      if (two) a1 = AddPairCount(a1, qv, refs.Block(b + 1), k, words);
    }
    StorePair(a0, a1, std::min(two ? 8 : 4, refs.rows - 4 * b), out + 4 * (b - b0));
  }
}

OPENABLE_AVX512 void Avx512Kernel(const std::uint64_t* q, const PackedRows& refs, int b0, int b1,
                                  float* out) {
  switch (refs.words) {
    case 4:
      return Avx512Blocks<2>(q, refs, b0, b1, out);  // 256 bits (LDB, ORB)
    case 8:
      return Avx512Blocks<4>(q, refs, b0, b1, out);  // 512 bits (BRISK)
    case 22:
      return Avx512Blocks<11>(q, refs, b0, b1, out);  // 1386 bits (LDB's largest)
    default:
      return Avx512Blocks<0>(q, refs, b0, b1, out);
  }
}

struct KernelChoice {
  Kernel kernel;
  const char* name;
};

bool HasAvx512Popcount() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512vpopcntdq") &&
         __builtin_cpu_supports("popcnt");
}

KernelChoice Best() {
  __builtin_cpu_init();
  if (HasAvx512Popcount()) return {Avx512Kernel, "avx512"};
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt"))
    return {Avx2Kernel, "avx2"};
  if (__builtin_cpu_supports("popcnt")) return {PopcntKernel, "popcnt"};
  return {PortableKernel, "portable"};
}

std::atomic<int> g_forced{static_cast<int>(HammingKernel::kAuto)};

KernelChoice Current() {
  static const KernelChoice best = Best();
  switch (static_cast<HammingKernel>(g_forced.load())) {
    case HammingKernel::kPortable:
      return {PortableKernel, "portable"};
    case HammingKernel::kPopcnt:
      return {PopcntKernel, "popcnt"};
    case HammingKernel::kAvx2:
      return {Avx2Kernel, "avx2"};
    case HammingKernel::kAvx512:
      return {Avx512Kernel, "avx512"};
    default:
      return best;
  }
}

// Rows [r0, r1) of `queries` against the references of blocks [first, last) (every block by
// default), into out rows (stride in floats; column 0 = reference 4 * first).
// Blocked: a group of queries runs over a slice of references that stays in L1/L2 cache.
void QueryRange(const std::vector<std::uint64_t>& qwords, int r0, int r1, const PackedRows& refs,
                float* out, size_t stride, int first = 0, int last = -1) {
  const Kernel kernel = Current().kernel;
  const int words = refs.words;
  const int slice = std::max(8, 65536 / (32 * std::max(1, words)));  // 64 KB of references
  const int end = last < 0 ? refs.blocks : last;
  for (int b0 = first; b0 < end; b0 += slice) {
    const int b1 = std::min(end, b0 + slice);
    for (int r = r0; r < r1; ++r)
      kernel(qwords.data() + static_cast<size_t>(r) * words, refs, b0, b1,
             out + static_cast<size_t>(r - r0) * stride + 4 * static_cast<size_t>(b0 - first));
  }
}

std::vector<std::uint64_t> RowWords(const cv::Mat& m) {
  const int words = (m.cols + 7) / 8;
  std::vector<std::uint64_t> w(static_cast<size_t>(m.rows) * words, 0);
  for (int i = 0; i < m.rows; ++i)
    std::memcpy(w.data() + static_cast<size_t>(i) * words, m.ptr<std::uint8_t>(i), m.cols);
  return w;
}

// Runs body(row) for every row in [0, rows) on `threads` threads (ParallelFor: rows of a
// triangle differ in cost), reporting progress in pairs, one caller at a time.
template <typename Body, typename PairsOfRow>
void ParallelRows(int rows, int threads, const PairProgress& progress, PairsOfRow pairs_of_row,
                  std::int64_t total_pairs, Body body) {
  std::atomic<std::int64_t> done{0};
  std::mutex report_mutex;
  // Read outside the lock by the first check (ThreadSanitizer found the plain variable's race).
  std::atomic<std::int64_t> last_report{0};
  const std::int64_t report_step = std::max<std::int64_t>(1, total_pairs / 100);
  ParallelFor(rows, threads, [&](int i) {
    body(i);
    const std::int64_t now = done += pairs_of_row(i);
    if (progress && now - last_report.load(std::memory_order_relaxed) >= report_step) {
      std::lock_guard<std::mutex> lock(report_mutex);
      if (now - last_report.load(std::memory_order_relaxed) >= report_step) {
        last_report.store(now, std::memory_order_relaxed);
        progress(now, total_pairs);
      }
    }
  });
  if (progress) progress(done.load(), total_pairs);
}

// Runs body(r0, r1) over the n query rows of an n x m matrix in tasks of 16 rows (ParallelRows),
// reporting progress in pairs.
template <typename Body>
void InTasksOfRows(int n, int m, int threads, const PairProgress& progress, Body body) {
  constexpr int kRowsPerTask = 16;
  const int tasks = (n + kRowsPerTask - 1) / kRowsPerTask;
  auto pairs_of_task = [&](int t) -> std::int64_t {
    return static_cast<std::int64_t>(std::min(kRowsPerTask, n - t * kRowsPerTask)) * m;
  };
  ParallelRows(tasks, threads, progress, pairs_of_task, static_cast<std::int64_t>(n) * m,
               [&](int t) {
                 const int r0 = t * kRowsPerTask;
                 body(r0, std::min(n, r0 + kRowsPerTask));
               });
}

void CheckInputs(const cv::Mat& a, const cv::Mat& b, int depth, const char* what) {
  if (a.depth() != depth || a.channels() != 1)
    throw std::logic_error(std::string(what) + ": descriptors of the wrong type");
  if (!b.empty() && (b.depth() != depth || b.channels() != 1 || b.cols != a.cols))
    throw std::logic_error(std::string(what) + ": reference descriptors of another width/type");
}

}  // namespace

namespace {

// One pair, compiled twice: for baseline x86-64 (where __builtin_popcountll is a bit-twiddling
// routine) and with the POPCNT instruction.
template <int kUnused>
__attribute__((always_inline)) inline int PairBits(const std::uint8_t* a, const std::uint8_t* b,
                                                   int bytes) {
  int bits = 0;
  int k = 0;
  for (; k + 8 <= bytes; k += 8) {
    std::uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    bits += __builtin_popcountll(x ^ y);
  }
  for (; k < bytes; ++k) bits += __builtin_popcount(static_cast<unsigned>(a[k] ^ b[k]));
  return bits;
}

int PairBitsPortable(const std::uint8_t* a, const std::uint8_t* b, int bytes) {
  return PairBits<0>(a, b, bytes);
}

__attribute__((target("popcnt"))) int PairBitsPopcnt(const std::uint8_t* a, const std::uint8_t* b,
                                                     int bytes) {
  return PairBits<1>(a, b, bytes);
}

}  // namespace

int HammingDistance(const std::uint8_t* a, const std::uint8_t* b, int bytes) {
  static const bool popcnt = __builtin_cpu_supports("popcnt");
  return popcnt ? PairBitsPopcnt(a, b, bytes) : PairBitsPortable(a, b, bytes);
}

float L2Distance(const float* a, const float* b, int width) {
  double s = 0;
  for (int i = 0; i < width; ++i) {
    const double t = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    s += t * t;
  }
  return static_cast<float>(std::sqrt(s));
}

Metric MetricOfType(int type) {
  return CV_MAT_DEPTH(type) == CV_8U ? Metric::kHamming : Metric::kL2;
}

float RowDistance(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  return RowDistance(a, i, b, j, MetricOfType(a.type()));
}

float RowDistance(const cv::Mat& a, int i, const cv::Mat& b, int j, Metric metric) {
  switch (metric) {
    case Metric::kHamming:
      return static_cast<float>(
          HammingDistance(a.ptr<std::uint8_t>(i), b.ptr<std::uint8_t>(j), a.cols));
    case Metric::kL1:
      return static_cast<float>(
          AbsoluteDifferences(a.ptr<std::uint8_t>(i), b.ptr<std::uint8_t>(j), a.cols));
    case Metric::kL2:
      break;
  }
  return L2Distance(a.ptr<float>(i), b.ptr<float>(j), a.cols);
}

cv::Mat1f Distances(const cv::Mat& a, const cv::Mat& b, Metric metric, int threads,
                    const PairProgress& progress) {
  switch (metric) {
    case Metric::kHamming:
      return HammingDistances(a, b, threads, progress);
    case Metric::kL1:
      return L1Distances(a, b, threads, progress);
    case Metric::kL2:
      break;
  }
  return L2Distances(a, b, threads, progress);
}

namespace {

std::int64_t AbsoluteDifferencesPortable(const std::uint8_t* a, const std::uint8_t* b, int bytes) {
  std::int64_t sum = 0;
  for (int k = 0; k < bytes; ++k) sum += a[k] > b[k] ? a[k] - b[k] : b[k] - a[k];
  return sum;
}

// 32 bytes a step with PSADBW (sums of absolute byte differences into four 64-bit lanes).
__attribute__((target("avx2"))) std::int64_t AbsoluteDifferencesAvx2(const std::uint8_t* a,
                                                                     const std::uint8_t* b,
                                                                     int bytes) {
  __m256i acc = _mm256_setzero_si256();
  int k = 0;
  for (; k + 32 <= bytes; k += 32) {
    const __m256i x = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + k));
    const __m256i y = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + k));
    acc = _mm256_add_epi64(acc, _mm256_sad_epu8(x, y));
  }
  alignas(32) std::uint64_t lanes[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), acc);
  return static_cast<std::int64_t>(lanes[0] + lanes[1] + lanes[2] + lanes[3]) +
         AbsoluteDifferencesPortable(a + k, b + k, bytes - k);
}

}  // namespace

std::int64_t AbsoluteDifferences(const std::uint8_t* a, const std::uint8_t* b, int bytes) {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2 ? AbsoluteDifferencesAvx2(a, b, bytes) : AbsoluteDifferencesPortable(a, b, bytes);
}

cv::Mat1f L1Distances(const cv::Mat& a, const cv::Mat& b, int threads,
                      const PairProgress& progress) {
  CheckInputs(a, b, CV_8U, "L1Distances");
  const cv::Mat& refs = b.empty() ? a : b;
  const int n = a.rows, m = refs.rows, w = a.cols;
  cv::Mat1f out = LargeMatrix(n, m);
  if (n == 0 || m == 0) return out;
  // Each task of query rows runs over slices of references that stay in cache.
  const int slice = std::max(16, (256 << 10) / std::max(1, w));
  InTasksOfRows(n, m, threads, progress, [&](int r0, int r1) {
    for (int j0 = 0; j0 < m; j0 += slice) {
      const int j1 = std::min(m, j0 + slice);
      for (int r = r0; r < r1; ++r) {
        const std::uint8_t* q = a.ptr<std::uint8_t>(r);
        float* o = out.ptr<float>(r);
        for (int j = j0; j < j1; ++j)
          o[j] = static_cast<float>(AbsoluteDifferences(q, refs.ptr<std::uint8_t>(j), w));
      }
    }
  });
  return out;
}

cv::Mat1f HammingDistances(const cv::Mat& a, const cv::Mat& b, int threads,
                           const PairProgress& progress) {
  CheckInputs(a, b, CV_8U, "HammingDistances");
  const cv::Mat& refs_mat = b.empty() ? a : b;
  const int n = a.rows, m = refs_mat.rows;
  cv::Mat1f out = LargeMatrix(n, m);
  if (n == 0 || m == 0) return out;
  // Every cell is computed, both triangles of a symmetric matrix included: rows are then
  // written in order, which costs less than mirroring one triangle column by column.
  const PackedRows refs = Pack(refs_mat);
  const std::vector<std::uint64_t> qwords = RowWords(a);
  InTasksOfRows(n, m, threads, progress, [&](int r0, int r1) {
    QueryRange(qwords, r0, r1, refs, out.ptr<float>(r0), out.step1());
  });
  return out;
}

struct HammingReferences::Packed {
  PackedRows rows;
};

HammingReferences::HammingReferences(const cv::Mat& references)
    : packed_(std::make_unique<Packed>()), bytes_(references.cols) {
  CheckInputs(references, cv::Mat(), CV_8U, "HammingReferences");
  packed_->rows = Pack(references);
}

HammingReferences::HammingReferences(const std::uint64_t* packed, int rows, int bytes)
    : packed_(std::make_unique<Packed>()), bytes_(bytes) {
  if (rows < 0 || bytes < 1)
    throw std::invalid_argument("HammingReferences: " + std::to_string(rows) + " rows of " +
                                std::to_string(bytes) + " bytes");
  PackedRows& p = packed_->rows;
  p.rows = rows;
  p.words = (bytes + 7) / 8;
  p.blocks = (rows + 3) / 4;
  p.base = packed;
}

std::size_t HammingReferences::PackedWords(int rows, int bytes) {
  return static_cast<std::size_t>((rows + 3) / 4) * static_cast<std::size_t>((bytes + 7) / 8) * 4;
}

const std::uint64_t* HammingReferences::PackedData() const { return packed_->rows.base; }

HammingReferences::~HammingReferences() = default;

int HammingReferences::Size() const { return packed_->rows.rows; }

void HammingReferences::Distances(const std::uint8_t* query, float* out) const {
  std::uint64_t q[64];
  std::vector<std::uint64_t> heap;
  std::uint64_t* words = q;
  const int n = packed_->rows.words;
  if (n > 64) {
    heap.resize(static_cast<size_t>(n));
    words = heap.data();
  }
  std::fill(words, words + n, 0);
  std::memcpy(words, query, static_cast<size_t>(bytes_));
  Current().kernel(words, packed_->rows, 0, packed_->rows.blocks, out);
}

void HammingReferences::DistancesInto(const cv::Mat& queries, cv::Mat1f& out, int threads) const {
  if (queries.depth() != CV_8U || queries.cols != bytes_)
    throw std::logic_error("HammingReferences::DistancesInto: queries of another width/type");
  const int n = queries.rows, m = Size();
  if (out.rows != n || out.cols != m) out = LargeMatrix(n, m);
  if (n == 0 || m == 0) return;
  const std::vector<std::uint64_t> qwords = RowWords(queries);
  InTasksOfRows(n, m, threads, {}, [&](int r0, int r1) {
    QueryRange(qwords, r0, r1, packed_->rows, out.ptr<float>(r0), out.step1());
  });
}

void HammingReferences::DistancesInto(const cv::Mat& queries, int first, int last, float* out,
                                      std::size_t stride) const {
  if (queries.depth() != CV_8U || queries.cols != bytes_)
    throw std::logic_error("HammingReferences::DistancesInto: queries of another width/type");
  if (first % 4 != 0 || first < 0 || last < first || last > Size())
    throw std::logic_error("HammingReferences::DistancesInto: columns not a range of blocks");
  if (queries.rows == 0 || last == first) return;
  const std::vector<std::uint64_t> qwords = RowWords(queries);
  QueryRange(qwords, 0, queries.rows, packed_->rows, out, stride, first / 4, (last + 3) / 4);
}

const char* HammingKernelName() { return Current().name; }

bool ForceHammingKernel(HammingKernel kernel) {
  __builtin_cpu_init();
  const bool avx512 = HasAvx512Popcount();
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("popcnt");
  const bool popcnt = __builtin_cpu_supports("popcnt");
  if ((kernel == HammingKernel::kAvx512 && !avx512) || (kernel == HammingKernel::kAvx2 && !avx2) ||
      (kernel == HammingKernel::kPopcnt && !popcnt))
    return false;
  g_forced = static_cast<int>(kernel);
  return true;
}

namespace {

// L2 matrices are computed in tiles of kL2Tile x kL2Tile cells (512 rather than 256: OpenBLAS's
// packing of operands is shared by more cells; docs/benchmarks.md, "Matching kernels"), each by
// one product on one thread
// (MultiplyTransposed) and turned into distances while it is in cache. A cell's float depends
// only on the product it comes from, and every path computes a cell in the same product: the
// tile of its row blocks (I, J) counted from the first row of each operand, and for a
// symmetric matrix the tile (max(I, J), min(I, J)), lower triangle, read mirrored. So a
// symmetric matrix costs half the arithmetic, and its rows computed apart (a run spread over
// processes, L2DistanceRows) are the same floats whatever OpenBLAS's kernels do with the
// shapes and the order of operands.
constexpr int kTile = kL2Tile;

// Relative size below which |a|^2 + |b|^2 - 2ab has lost most of its digits: such cells
// (near-duplicate rows) are summed directly.
constexpr float kCancellation = 1e-3f;

struct L2Operands {
  cv::Mat a, b;               // continuous rows
  std::vector<float> na, nb;  // squared norms
  int Tiles(const cv::Mat& m) const { return (m.rows + kTile - 1) / kTile; }
};

// Squared norms summed in double and rounded once.
std::vector<float> SquaredNorms(const cv::Mat& rows) {
  std::vector<float> out(static_cast<size_t>(rows.rows));
  for (int i = 0; i < rows.rows; ++i) {
    const float* r = rows.ptr<float>(i);
    double sum = 0.0;
    for (int k = 0; k < rows.cols; ++k) sum += static_cast<double>(r[k]) * r[k];
    out[static_cast<size_t>(i)] = static_cast<float>(sum);
  }
  return out;
}

L2Operands MakeOperands(const cv::Mat& a, const cv::Mat& b) {
  L2Operands o;
  // Descriptor rows may be a view with gaps: the product wants rows at a fixed stride.
  o.a = a.isContinuous() ? a : a.clone();
  o.na = SquaredNorms(o.a);
  if (b.empty()) {
    o.b = o.a;
    o.nb = o.na;
  } else {
    o.b = b.isContinuous() ? b : b.clone();
    o.nb = SquaredNorms(o.b);
  }
  return o;
}

// Tile (I, J): distances of the rows of block I of a to those of block J of b, into c (rows
// ldc floats apart).
void L2Tile(const L2Operands& o, int I, int J, float* c, size_t ldc) {
  const int r0 = I * kTile, rows = std::min(kTile, o.a.rows - r0);
  const int c0 = J * kTile, cols = std::min(kTile, o.b.rows - c0);
  const int d = o.a.cols;
  MultiplyTransposed(o.a.ptr<float>(r0), rows, static_cast<int>(o.a.step1()), o.b.ptr<float>(c0),
                     cols, static_cast<int>(o.b.step1()), d, c, static_cast<int>(ldc));
  const float* nb = o.nb.data() + c0;
  for (int r = 0; r < rows; ++r) {
    float* row = c + static_cast<size_t>(r) * ldc;
    const float ni = o.na[static_cast<size_t>(r0 + r)];
    bool cancelled = false;
    for (int j = 0; j < cols; ++j) {
      const float scale = ni + nb[j];
      const float sq = scale - 2.0f * row[j];
      cancelled |= sq < kCancellation * scale;
      row[j] = std::sqrt(std::max(sq, 0.0f));
    }
    if (!cancelled) continue;
    for (int j = 0; j < cols; ++j)
      if (row[j] * row[j] < kCancellation * (ni + nb[j]))
        row[j] = L2Distance(o.a.ptr<float>(r0 + r), o.b.ptr<float>(c0 + j), d);
  }
}

}  // namespace

cv::Mat1f L2Distances(const cv::Mat& a, const cv::Mat& b, int threads,
                      const PairProgress& progress) {
  CheckInputs(a, b, CV_32F, "L2Distances");
  const bool same = b.empty();
  const int n = a.rows, m = same ? n : b.rows;
  cv::Mat1f out = LargeMatrix(n, m);
  if (n == 0 || m == 0) return out;
  const L2Operands o = MakeOperands(a, b);
  const int ti = o.Tiles(o.a), tj = o.Tiles(o.b);
  // The tiles in order of rows; a symmetric matrix takes those of the lower triangle.
  std::vector<std::pair<int, int>> tiles;
  for (int I = 0; I < ti; ++I)
    for (int J = 0; J < (same ? I + 1 : tj); ++J) tiles.emplace_back(I, J);
  const auto cells = [&](int t) -> std::int64_t {
    const auto [I, J] = tiles[static_cast<size_t>(t)];
    return static_cast<std::int64_t>(std::min(kTile, n - I * kTile)) *
           std::min(kTile, m - J * kTile);
  };
  std::int64_t total = 0;
  for (int t = 0; t < static_cast<int>(tiles.size()); ++t) total += cells(t);
  // Progress in cells of the whole matrix, of which a symmetric one computes about half.
  const std::int64_t whole = static_cast<std::int64_t>(n) * m;
  const PairProgress in_cells = progress ? PairProgress([&](std::int64_t done, std::int64_t) {
    progress(static_cast<std::int64_t>(static_cast<double>(done) / total * whole), whole);
  })
                                         : PairProgress();
  ParallelRows(static_cast<int>(tiles.size()), threads, in_cells, cells, total, [&](int t) {
    const auto [I, J] = tiles[static_cast<size_t>(t)];
    L2Tile(o, I, J, out.ptr<float>(I * kTile) + J * kTile, out.step1());
    if (!same) return;
    // The upper triangle from the lower, while the tile is in cache: tile (J, I) is tile (I, J)
    // transposed; a diagonal tile's upper half is its lower half mirrored, its diagonal zero.
    const int r0 = I * kTile, c0 = J * kTile;
    const int rows = std::min(kTile, n - r0), cols = std::min(kTile, m - c0);
    if (I != J) {
      cv::Mat1f upper = out(cv::Rect(r0, c0, rows, cols));
      cv::transpose(out(cv::Rect(c0, r0, cols, rows)), upper);
      return;
    }
    for (int r = 0; r < rows; ++r) {
      float* row = out.ptr<float>(r0 + r) + c0;
      row[r] = 0.0f;
      for (int j = r + 1; j < cols; ++j) row[j] = out(r0 + j, c0 + r);
    }
  });
  return out;
}

cv::Mat1f L2DistanceRows(const cv::Mat& a, int first, int last, int threads,
                         const PairProgress& progress) {
  CheckInputs(a, cv::Mat(), CV_32F, "L2DistanceRows");
  if (first < 0 || last > a.rows || first > last)
    throw std::logic_error("L2DistanceRows: rows out of range");
  const int n = a.rows, rows = last - first;
  cv::Mat1f out = LargeMatrix(rows, n);
  if (rows == 0 || n == 0) return out;
  const L2Operands o = MakeOperands(a, cv::Mat());
  const int blocks = o.Tiles(o.a);
  const int i0 = first / kTile, i1 = (last - 1) / kTile + 1;
  const int tiles = (i1 - i0) * blocks;
  const auto cells = [&](int t) -> std::int64_t {
    const int I = i0 + t / blocks, J = t % blocks;
    const int r0 = std::max(first, I * kTile), r1 = std::min(last, I * kTile + kTile);
    return static_cast<std::int64_t>(r1 - r0) * std::min(kTile, n - J * kTile);
  };
  const std::int64_t total = static_cast<std::int64_t>(rows) * n;
  ParallelRows(tiles, threads, progress, cells, total, [&](int t) {
    const int I = i0 + t / blocks, J = t % blocks;
    // The tile that holds these cells in the symmetric matrix: (I, J) below the diagonal,
    // (J, I) read transposed above it; the diagonal tile's upper half mirrored from its lower.
    const int hi = std::max(I, J), lo = std::min(I, J);
    std::vector<float> tile(static_cast<size_t>(kTile) * kTile);
    L2Tile(o, hi, lo, tile.data(), kTile);
    const auto at = [&](int i, int j) {  // cell (i, j) of the symmetric matrix, i, j in the tile
      const int gi = std::max(i, j), gj = std::min(i, j);
      const int ri = gi - hi * kTile, rj = gj - lo * kTile;
      return gi == gj ? 0.0f : tile[static_cast<size_t>(ri) * kTile + rj];
    };
    const int r0 = std::max(first, I * kTile), r1 = std::min(last, I * kTile + kTile);
    const int c0 = J * kTile, c1 = std::min(n, c0 + kTile);
    for (int i = r0; i < r1; ++i) {
      float* o_row = out.ptr<float>(i - first);
      for (int j = c0; j < c1; ++j) o_row[j] = at(i, j);
    }
  });
  return out;
}

}  // namespace openable
