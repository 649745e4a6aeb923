#include "matching/blas.h"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "matching/distances.h"

namespace openable {
namespace {

// tests/CMakeLists.txt runs these tests again with OPENBLAS_CORETYPE naming each family of
// OpenBLAS kernels; those the CPU cannot run are skipped.
bool KernelsRunHere() {
  const char* core = std::getenv("OPENBLAS_CORETYPE");
  if (!core) return true;
  const std::string c = core;
  __builtin_cpu_init();
  if (c == "SkylakeX")
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
  if (c == "Haswell") return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (c == "Sandybridge") return __builtin_cpu_supports("avx");
  return true;  // Prescott: SSE3, every x86-64 CPU of these machines
}

#define SKIP_UNLESS_KERNELS_RUN_HERE()                                                  \
  if (!KernelsRunHere())                                                                \
  GTEST_SKIP() << "this CPU cannot run OpenBLAS's " << std::getenv("OPENBLAS_CORETYPE") \
               << " kernels"

cv::Mat1f Normal(int rows, int cols, unsigned seed, float offset = 0.0f) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 1.f);
  cv::Mat1f m(rows, cols);
  for (auto& v : m) v = offset + g(rng);
  return m;
}

// C = A B^T of rows [r0, r1) of A against rows [c0, c1) of B, in a matrix of its own.
cv::Mat1f Product(const cv::Mat1f& a, int r0, int r1, const cv::Mat1f& b, int c0, int c1) {
  cv::Mat1f c(r1 - r0, c1 - c0, -1.0f);
  MultiplyTransposed(a.ptr<float>(r0), r1 - r0, static_cast<int>(a.step1()), b.ptr<float>(c0),
                     c1 - c0, static_cast<int>(b.step1()), a.cols, c.ptr<float>(0),
                     static_cast<int>(c.step1()));
  return c;
}

// Each cell against the dot product summed in long double, within the float error bound of a
// sum of `width` products (Higham: n u sum |a_k b_k|, with room for the FMA order).
TEST(MultiplyTransposed, EachCellIsTheDotProductWithinFloatRounding) {
  SKIP_UNLESS_KERNELS_RUN_HERE();
  const cv::Mat1f a = Normal(70, 1764, 1), b = Normal(45, 1764, 2);
  const cv::Mat1f c = Product(a, 0, a.rows, b, 0, b.rows);
  const double u = std::ldexp(1.0, -24);
  for (int i = 0; i < a.rows; ++i)
    for (int j = 0; j < b.rows; ++j) {
      long double dot = 0, magnitude = 0;
      for (int k = 0; k < a.cols; ++k) {
        dot += static_cast<long double>(a(i, k)) * b(j, k);
        magnitude += std::fabs(static_cast<long double>(a(i, k)) * b(j, k));
      }
      ASSERT_NEAR(c(i, j), static_cast<double>(dot),
                  static_cast<double>(a.cols * u * magnitude) + 1e-30)
          << i << "," << j;
    }
  // Hand-worked: (1, 2, 3) . (4, 5, 6) = 32, (1, 2, 3) . (-1, 0, 1) = 2.
  const cv::Mat1f x = (cv::Mat1f(1, 3) << 1, 2, 3);
  const cv::Mat1f y = (cv::Mat1f(2, 3) << 4, 5, 6, -1, 0, 1);
  const cv::Mat1f xy = Product(x, 0, 1, y, 0, 2);
  EXPECT_EQ(xy(0, 0), 32.0f);
  EXPECT_EQ(xy(0, 1), 2.0f);
}

// Products running on several threads at once give each the floats it gives alone.
TEST(MultiplyTransposed, ProductsOnSeveralThreadsAtOnceAreTheProductsAlone) {
  SKIP_UNLESS_KERNELS_RUN_HERE();
  const cv::Mat1f a = Normal(300, 1764, 3), b = Normal(280, 1764, 4);
  const cv::Mat1f alone = Product(a, 0, a.rows, b, 0, b.rows);
  std::vector<cv::Mat1f> each(4);
  std::vector<std::thread> threads;
  for (auto& e : each) threads.emplace_back([&] { e = Product(a, 0, a.rows, b, 0, b.rows); });
  for (auto& t : threads) t.join();
  for (const auto& e : each) ASSERT_EQ(cv::norm(e, alone, cv::NORM_INF), 0.0);
}

// L2 matrices against the direct sum (every cell within float rounding, L2Distance in double),
// over sizes around the tiles of kL2Tile rows, on 1, 2 and 3 threads: the same floats on each.
TEST(L2Distances, TilesMatchTheDirectSumOnAnyThreadCount) {
  SKIP_UNLESS_KERNELS_RUN_HERE();
  const int t = kL2Tile;
  const cv::Mat1f a = Normal(t + 18, 300, 5, 2.0f), b = Normal(t / 2 + 1, 300, 6, 2.0f);
  const cv::Mat1f one = L2Distances(a, b, 1), self_one = L2Distances(a, cv::Mat(), 1);
  for (int i = 0; i < a.rows; i += 7)
    for (int j = 0; j < b.rows; ++j) {
      const double direct = L2Distance(a.ptr<float>(i), b.ptr<float>(j), a.cols);
      ASSERT_NEAR(one(i, j), direct, 2e-5 * direct) << i << "," << j;
    }
  for (int i = 0; i < a.rows; i += 5)
    for (int j = 0; j < a.rows; ++j) {
      const double direct = L2Distance(a.ptr<float>(i), a.ptr<float>(j), a.cols);
      ASSERT_NEAR(self_one(i, j), direct, 2e-5 * direct) << i << "," << j;
      ASSERT_EQ(self_one(i, j), self_one(j, i));
    }
  for (const int threads : {2, 3}) {
    EXPECT_EQ(cv::norm(L2Distances(a, b, threads), one, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(L2Distances(a, cv::Mat(), threads), self_one, cv::NORM_INF), 0.0);
  }
}

// The promise a run spread over processes relies on: any rows of the symmetric matrix computed
// apart are its rows, bit for bit, whatever OpenBLAS's kernels do with the shapes of products.
TEST(L2DistanceRows, AreTheRowsOfTheSymmetricMatrixBitForBit) {
  SKIP_UNLESS_KERNELS_RUN_HERE();
  const int t = kL2Tile, n = 2 * t + 100;  // three row blocks, the last one partial
  const cv::Mat1f a = Normal(n, 1764, 7, 0.5f);
  const cv::Mat1f self = L2Distances(a, cv::Mat(), 2);
  for (const auto& [first, last] : std::vector<std::pair<int, int>>{
           {0, n}, {t, 2 * t}, {2 * t, n}, {3, t / 2}, {t - 1, 2 * t + 1}, {n - 1, n}, {10, 10}}) {
    const cv::Mat1f rows = L2DistanceRows(a, first, last, 3);
    ASSERT_EQ(rows.rows, last - first);
    if (rows.empty()) continue;
    EXPECT_EQ(cv::norm(rows, self.rowRange(first, last), cv::NORM_INF), 0.0)
        << "rows [" << first << ", " << last << ")";
  }
}

// Unless the user named the kernels, a CPU with AVX2 runs kernels that use it (OpenBLAS's own
// choice, or the one OpenABLE makes when OpenBLAS does not know the CPU).
TEST(Blas, RunsKernelsOfTheCpusInstructionSets) {
  const std::string d = BlasDescription();
  ASSERT_NE(d.find("OpenBLAS"), std::string::npos) << d;
  if (std::getenv("OPENBLAS_CORETYPE")) GTEST_SKIP() << "kernels named by OPENBLAS_CORETYPE";
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma"))
    GTEST_SKIP() << "a CPU without AVX2";
  bool avx2_kernels = false;
  for (const char* core : {"kernels Haswell", "kernels Zen", "kernels SkylakeX",
                           "kernels Cooperlake", "kernels SapphireRapids"})
    avx2_kernels |= d.find(core) != std::string::npos;
  EXPECT_TRUE(avx2_kernels) << d;
}

// While a BlasOnOneThread lives (FAISS's k-means runs), OpenBLAS's process-wide thread count is
// 1; the host's own count comes back when the last one ends, also when they overlap.
TEST(BlasOnOneThread, SetsOneThreadAndPutsTheHostsCountBack) {
  void* handle = dlopen("libopenblas.so.0", RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) GTEST_SKIP() << "no OpenBLAS";
  const auto set = reinterpret_cast<void (*)(int)>(dlsym(handle, "openblas_set_num_threads"));
  const auto get = reinterpret_cast<int (*)()>(dlsym(handle, "openblas_get_num_threads"));
  ASSERT_TRUE(set != nullptr && get != nullptr);
  const int before = get();
  set(3);
  ASSERT_EQ(get(), 3) << "this OpenBLAS does not take a thread count";
  {
    const BlasOnOneThread outer;
    EXPECT_EQ(get(), 1);
    {
      const BlasOnOneThread inner;
      EXPECT_EQ(get(), 1);
    }
    EXPECT_EQ(get(), 1);  // the outer one still runs
  }
  EXPECT_EQ(get(), 3);
  set(before);
  dlclose(handle);
}

}  // namespace
}  // namespace openable
