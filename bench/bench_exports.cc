// Exports of a 3576 x 3576 matrix (Nordland trimmed, both seasons): colour map, PNG encoding,
// .npy and text encoding. Items = matrix cells. OPENABLE_EXPORTS_MATRIX=FILE.npy takes the
// matrix of a real run (its Npy_name) instead of the synthetic one, as the run's Txt_name and
// Png_name see it (cells without a value, +inf, as the largest finite value).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "OpenABLE/io/npy.h"
#include "OpenABLE/outputs/matrix_files.h"
#include "OpenABLE/reports/figures.h"

namespace {

// A smooth matrix with a dark diagonal, compressed by PNG like a real one (not like noise).
cv::Mat1f Matrix(int n) {
  cv::Mat1f m(n, n);
  cv::RNG rng(3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      m(i, j) = std::min(1.0f, 0.3f + 0.5f * std::abs(i - j) / n + 0.05f * rng.uniform(0.f, 1.f));
  return m;
}

cv::Mat1f FromFile(const char* path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  cv::Mat1f m = openable::DecodeNpyMatrix(bytes, path);
  const cv::Mat1b empty = m == std::numeric_limits<float>::infinity();
  double largest = 0;
  cv::minMaxLoc(m, nullptr, &largest, nullptr, nullptr, ~empty);
  m.setTo(largest, empty);
  return m;
}

const cv::Mat1f& Shared() {
  static const cv::Mat1f m = std::getenv("OPENABLE_EXPORTS_MATRIX") != nullptr
                                 ? FromFile(std::getenv("OPENABLE_EXPORTS_MATRIX"))
                                 : Matrix(3576);
  return m;
}

void BM_Colorize(benchmark::State& state) {
  const cv::Mat1f& m = Shared();
  for (auto _ : state) benchmark::DoNotOptimize(openable::ColorizeMatrix(m, 4).data);
  state.SetItemsProcessed(state.iterations() * Shared().total());
}
BENCHMARK(BM_Colorize)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EncodePng(benchmark::State& state) {
  const cv::Mat3b image = openable::ColorizeMatrix(Shared(), 4);
  std::size_t bytes = 0;
  for (auto _ : state) benchmark::DoNotOptimize(bytes = openable::EncodePng(image).size());
  state.SetItemsProcessed(state.iterations() * Shared().total());
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_EncodePng)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same image through OpenCV's encoder (one thread, zlib, the same Sub filter, level 1 with
// the run-length strategy, as EncodePng wrote with zlib before libdeflate): the reference for
// its speed and size.
void BM_EncodePngOpenCv(benchmark::State& state) {
  const cv::Mat3b image = openable::ColorizeMatrix(Shared(), 4);
  std::vector<std::uint8_t> buf;
  for (auto _ : state) benchmark::DoNotOptimize(cv::imencode(".png", image, buf));
  state.SetItemsProcessed(state.iterations() * Shared().total());
  state.counters["bytes"] = static_cast<double>(buf.size());
}
BENCHMARK(BM_EncodePngOpenCv)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EncodeNpy(benchmark::State& state) {
  const cv::Mat1f& m = Shared();
  for (auto _ : state) benchmark::DoNotOptimize(openable::EncodeNpy(m).size());
  state.SetItemsProcessed(state.iterations() * Shared().total());
}
BENCHMARK(BM_EncodeNpy)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EncodeText(benchmark::State& state) {
  const cv::Mat1f& m = Shared();  // made or read before the timing
  std::size_t bytes = 0;
  for (auto _ : state) benchmark::DoNotOptimize(bytes = openable::EncodeText(m).size());
  state.SetItemsProcessed(state.iterations() * Shared().total());
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_EncodeText)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

// The text as a run writes it (Txt_name): piece after piece, never whole.
void BM_TextChunks(benchmark::State& state) {
  const cv::Mat1f& m = Shared();
  std::size_t bytes = 0;
  for (auto _ : state) {
    openable::TextChunks chunks(m);
    bytes = 0;
    for (std::string_view piece; chunks.Next(piece);) bytes += piece.size();
    benchmark::DoNotOptimize(bytes);
  }
  state.SetItemsProcessed(state.iterations() * m.total());
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_TextChunks)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
