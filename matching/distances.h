// Pairwise distances between descriptor rows: Hamming (Eq. 4 of the OpenABLE paper: a real
// count of differing bits, not the sum of XOR-ed bytes that the original computed) and L2
// (Eq. 8).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>

#include "OpenABLE/base/enum_names.h"

namespace openable {

// The distance of a kind of descriptor rows: Hamming (binary rows, CV_8U), L2 (vector rows,
// CV_32F), or L1, the sum of absolute differences of byte rows (CV_8U; SeqSLAM's SAD).
enum class Metric { kHamming, kL2, kL1 };
OPENABLE_ENUM_NAMES(Metric, "hamming", "l2", "l1")

// The metric rows of `type` have when none is said: Hamming for CV_8U, L2 for CV_32F.
Metric MetricOfType(int type);

// Called now and then with (cells done, cells in all) of the matrix computed; may be empty. Called
// from one thread at a time.
using PairProgress = std::function<void(std::int64_t done, std::int64_t total)>;

// Number of bits that differ between the byte strings a and b of `bytes` bytes.
int HammingDistance(const std::uint8_t* a, const std::uint8_t* b, int bytes);

// Sum of the absolute differences of the bytes of a and b (AVX2 PSADBW when the CPU has it).
std::int64_t AbsoluteDifferences(const std::uint8_t* a, const std::uint8_t* b, int bytes);

// L1 distances (sums of absolute byte differences) between every row of `a` (N x W, CV_8U)
// and every row of `b` (M x W, CV_8U); b empty means b = a. As HammingDistances otherwise.
cv::Mat1f L1Distances(const cv::Mat& a, const cv::Mat& b = cv::Mat(), int threads = 0,
                      const PairProgress& progress = {});

// Euclidean distance between two rows of `width` floats, with the differences and their squares
// summed in double precision and rounded once to float: the exact distance of a pair.
float L2Distance(const float* a, const float* b, int width);

// The distance of one pair of rows: row i of `a` and row j of `b` (same type and width):
// HammingDistance for CV_8U rows, L2Distance for CV_32F rows (or `metric`). Every distance of
// single pairs (candidates rescored after an approximate search, sequence cells computed one
// by one) comes from here; the matrices below agree with it (L2: within float rounding).
float RowDistance(const cv::Mat& a, int i, const cv::Mat& b, int j);
float RowDistance(const cv::Mat& a, int i, const cv::Mat& b, int j, Metric metric);

// The matrix of `metric` between the rows of `a` and `b` (HammingDistances, L2Distances or
// L1Distances).
cv::Mat1f Distances(const cv::Mat& a, const cv::Mat& b, Metric metric, int threads = 0,
                    const PairProgress& progress = {});

// Distances between every row of `a` (N x W, CV_8U) and every row of `b` (M x W, CV_8U):
// an N x M matrix of bit counts, stored as float. When `b` is empty, b = a and the result
// is symmetric with a zero diagonal. Every cell is computed (for a symmetric matrix too: rows
// written in order cost less than a mirrored triangle). Blocks of rows run in parallel on
// `threads` threads (0 = all cores).
cv::Mat1f HammingDistances(const cv::Mat& a, const cv::Mat& b = cv::Mat(), int threads = 0,
                           const PairProgress& progress = {});

// Hamming kernels. The fastest one the CPU has is chosen at run time (AVX-512 with VPOPCNTQ >
// AVX2 > POPCNT > portable), so one binary runs everywhere.
enum class HammingKernel { kAuto, kPortable, kPopcnt, kAvx2, kAvx512 };
// Name of the kernel in use: "avx512", "avx2", "popcnt" or "portable".
const char* HammingKernelName();
// Forces a kernel for the whole process (tests and benchmarks); kAuto restores the choice.
// Returns false, changing nothing, when the CPU lacks it.
bool ForceHammingKernel(HammingKernel kernel);

// Distances of one query row (`bytes` bytes, the width of the references) to every reference
// of a packed set, with the kernel in use. For kernels and benchmarks that reuse an output.
class HammingReferences {
 public:
  explicit HammingReferences(const cv::Mat& references);  // N x W, CV_8U
  // References already packed (the words of PackedData() of `rows` rows of `bytes` bytes,
  // PackedWords(rows, bytes) of them, in this host's byte order), read in place: `packed`
  // must outlive this object (a saved index used where a mapped file holds it).
  HammingReferences(const std::uint64_t* packed, int rows, int bytes);
  ~HammingReferences();
  // The packed form the kernels read: 64-bit words, in blocks of four references word-major
  // inside a block, each row zero-padded to whole words. PackedWords(Size(), width) words.
  const std::uint64_t* PackedData() const;
  static std::size_t PackedWords(int rows, int bytes);
  HammingReferences(const HammingReferences&) = delete;
  HammingReferences& operator=(const HammingReferences&) = delete;
  int Size() const;
  // out[j] = bits differing between `query` and reference j, for j in [0, Size()).
  void Distances(const std::uint8_t* query, float* out) const;
  // Every row of `queries` (CV_8U, same width) against every reference, into `out` (resized
  // to queries.rows x Size(), reused when already that size). Blocks of rows in parallel.
  void DistancesInto(const cv::Mat& queries, cv::Mat1f& out, int threads = 0) const;
  // Every row of `queries` against references [first, last) only, on the calling thread: row r
  // of the queries at out + r * stride, column 0 = reference `first`. `first` is a multiple of
  // 4 (references are packed in blocks of four) and the last block is written whole: `out`
  // holds round_up(last - first, 4) columns, or up to the last reference.
  void DistancesInto(const cv::Mat& queries, int first, int last, float* out,
                     std::size_t stride) const;

 private:
  struct Packed;
  std::unique_ptr<Packed> packed_;
  int bytes_ = 0;
};

// Euclidean distances between the rows of `a` (N x W, CV_32F) and `b` (M x W, CV_32F); b
// empty means b = a (symmetric, zero diagonal, half the arithmetic). Computed through one
// matrix product, |a|^2 + |b|^2 - 2 a.b (OpenBLAS: matching/blas.h); cells where that form
// loses precision to cancellation (distance small against the norms) are recomputed directly,
// so every cell is within float rounding of the direct sum.
cv::Mat1f L2Distances(const cv::Mat& a, const cv::Mat& b = cv::Mat(), int threads = 0,
                      const PairProgress& progress = {});

// Rows [first, last) of L2Distances(a) (the symmetric matrix), the same floats: for a run
// spread over processes, each computing its own rows (best on multiples of kL2Tile, the rows
// and columns of the tiles L2 matrices are computed in: a tile split between two processes is
// computed by both).
inline constexpr int kL2Tile = 512;
cv::Mat1f L2DistanceRows(const cv::Mat& a, int first, int last, int threads = 0,
                         const PairProgress& progress = {});

}  // namespace openable
