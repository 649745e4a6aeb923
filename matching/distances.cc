#include "matching/distances.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <Eigen/Core>

namespace openable {
namespace {

// Descriptor rows copied into 64-bit words (zero-padded), so the kernel XORs and counts whole
// words. The standard library has no popcount before C++20; GCC's builtin compiles to the
// POPCNT instruction in the clone selected at run time on CPUs that have it (target_clones),
// and to a portable fallback elsewhere, so one binary runs everywhere.
struct WordRows {
  int words = 0;
  int rows = 0;
  std::vector<std::uint64_t> data;
  const std::uint64_t* Row(int i) const { return data.data() + static_cast<size_t>(i) * words; }
};

WordRows ToWords(const cv::Mat& m) {
  WordRows w;
  w.rows = m.rows;
  w.words = (m.cols + 7) / 8;
  w.data.assign(static_cast<size_t>(w.rows) * w.words, 0);
  for (int i = 0; i < m.rows; ++i)
    std::memcpy(w.data.data() + static_cast<size_t>(i) * w.words, m.ptr<std::uint8_t>(i),
                m.cols);
  return w;
}

__attribute__((target_clones("popcnt", "default"))) void HammingRow(
    const std::uint64_t* q, const WordRows& refs, int words, int begin, int end, float* out) {
  for (int j = begin; j < end; ++j) {
    const std::uint64_t* r = refs.Row(j);
    int bits = 0;
    for (int k = 0; k < words; ++k) bits += __builtin_popcountll(q[k] ^ r[k]);
    out[j] = static_cast<float>(bits);
  }
}

int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

// Runs body(row) for every row in [0, rows) on `threads` threads, handing rows out one at a
// time (rows of a triangle differ in cost). Reports progress in pairs from the calling thread
// of the first worker only, to keep the callback single-threaded.
template <typename Body, typename PairsOfRow>
void ParallelRows(int rows, int threads, const PairProgress& progress, PairsOfRow pairs_of_row,
                  std::int64_t total_pairs, Body body) {
  std::atomic<int> next{0};
  std::atomic<std::int64_t> done{0};
  std::mutex report_mutex;
  std::int64_t last_report = 0;
  const std::int64_t report_step = std::max<std::int64_t>(1, total_pairs / 100);
  auto worker = [&]() {
    for (int i = next++; i < rows; i = next++) {
      body(i);
      const std::int64_t now = done += pairs_of_row(i);
      if (progress && now - last_report >= report_step) {
        std::lock_guard<std::mutex> lock(report_mutex);
        if (now - last_report >= report_step) {
          last_report = now;
          progress(now, total_pairs);
        }
      }
    }
  };
  const int n = std::min(ResolveThreads(threads), std::max(rows, 1));
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (progress) progress(done.load(), total_pairs);
}

void CheckInputs(const cv::Mat& a, const cv::Mat& b, int depth, const char* what) {
  if (a.depth() != depth || a.channels() != 1)
    throw std::logic_error(std::string(what) + ": descriptors of the wrong type");
  if (!b.empty() && (b.depth() != depth || b.channels() != 1 || b.cols != a.cols))
    throw std::logic_error(std::string(what) + ": reference descriptors of another width/type");
}

}  // namespace

int HammingDistance(const std::uint8_t* a, const std::uint8_t* b, int bytes) {
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

cv::Mat1f HammingDistances(const cv::Mat& a, const cv::Mat& b, int threads,
                           const PairProgress& progress) {
  CheckInputs(a, b, CV_8U, "HammingDistances");
  const bool same = b.empty();
  const WordRows qa = ToWords(a);
  const WordRows qb = same ? WordRows() : ToWords(b);
  const WordRows& refs = same ? qa : qb;
  const int n = qa.rows, m = refs.rows;
  cv::Mat1f out(n, m, 0.0f);
  if (n == 0 || m == 0) return out;
  // For a symmetric matrix only the upper triangle j > i is computed, then mirrored.
  auto pairs_of_row = [&](int i) -> std::int64_t { return same ? n - 1 - i : m; };
  const std::int64_t total =
      same ? static_cast<std::int64_t>(n) * (n - 1) / 2 : static_cast<std::int64_t>(n) * m;
  ParallelRows(n, threads, progress, pairs_of_row, total, [&](int i) {
    HammingRow(qa.Row(i), refs, qa.words, same ? i + 1 : 0, m, out.ptr<float>(i));
  });
  if (same) cv::completeSymm(out, /*lowerToUpper=*/false);
  return out;
}

cv::Mat1f L2Distances(const cv::Mat& a, const cv::Mat& b, int threads,
                      const PairProgress& progress) {
  CheckInputs(a, b, CV_32F, "L2Distances");
  const bool same = b.empty();
  const cv::Mat& bb = same ? a : b;
  const int n = a.rows, m = bb.rows, d = a.cols;
  cv::Mat1f out(n, m, 0.0f);
  if (n == 0 || m == 0) return out;
  using RowMat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  // Descriptor rows may not be continuous (a view); copy once into Eigen's layout.
  RowMat ea(n, d), eb(m, d);
  for (int i = 0; i < n; ++i) std::memcpy(ea.row(i).data(), a.ptr<float>(i), d * sizeof(float));
  for (int j = 0; j < m; ++j) std::memcpy(eb.row(j).data(), bb.ptr<float>(j), d * sizeof(float));
  const Eigen::VectorXf na = ea.rowwise().squaredNorm();
  const Eigen::VectorXf nb = eb.rowwise().squaredNorm();
  // One block of rows at a time keeps the product's memory bounded and lets rows run in
  // parallel and report progress.
  constexpr int kBlock = 256;
  const int blocks = (n + kBlock - 1) / kBlock;
  auto pairs_of_block = [&](int blk) -> std::int64_t {
    return static_cast<std::int64_t>(std::min(kBlock, n - blk * kBlock)) * m;
  };
  // Relative size below which |a|^2 + |b|^2 - 2ab has lost most of its digits.
  constexpr float kCancellation = 1e-3f;
  ParallelRows(blocks, threads, progress, pairs_of_block, static_cast<std::int64_t>(n) * m,
               [&](int blk) {
                 const int r0 = blk * kBlock, rows = std::min(kBlock, n - r0);
                 const RowMat g = ea.middleRows(r0, rows) * eb.transpose();
                 for (int r = 0; r < rows; ++r) {
                   const int i = r0 + r;
                   float* o = out.ptr<float>(i);
                   for (int j = 0; j < m; ++j) {
                     const float scale = na[i] + nb[j];
                     float sq = scale - 2.0f * g(r, j);
                     if (sq < kCancellation * scale) sq = (ea.row(i) - eb.row(j)).squaredNorm();
                     o[j] = std::sqrt(std::max(sq, 0.0f));
                   }
                 }
               });
  if (same) {
    for (int i = 0; i < n; ++i) out(i, i) = 0.0f;
    cv::completeSymm(out, /*lowerToUpper=*/false);  // exact symmetry despite rounding order
  }
  return out;
}

}  // namespace openable
