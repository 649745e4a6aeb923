// Stereo pipeline on the real EuRoC pairs (../shared/datasets/euroc_stereo_pairs; skipped with a
// message when absent): time per pair of each stage (rectification, SGBM, D-LDB description,
// and the whole stereo frame as the pipeline reads it), and, printed first, the Hamming
// distances of the pairs under a few description settings (docs/benchmarks.md).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "OpenABLE/describe/describe.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/stereo/stereo_source.h"
#include "descriptors/registry.h"
#include "tests/tools/euroc_calibration.h"

namespace {

namespace fs = std::filesystem;
using namespace openable;  // NOLINT

const std::string kDir = OPENABLE_DATASETS_DIR "/euroc_stereo_pairs";

struct Data {
  StereoCalibration calibration;
  std::unique_ptr<StereoRectifier> rectifier;
  DisparityOptions disparity;
  cv::Mat left[4], right[4];
  std::string folders;
};

const Data* Load() {
  static std::unique_ptr<Data> data;
  if (data) return data.get();
  if (!fs::exists(kDir)) return nullptr;
  data = std::make_unique<Data>();
  data->folders = (fs::temp_directory_path() / "openable_bench_stereo").string();
  fs::create_directories(data->folders + "/left");
  fs::create_directories(data->folders + "/right");
  for (int i = 0; i < 4; ++i) {
    const std::string n = std::to_string(i);
    fs::copy_file(kDir + "/left_img_" + n + ".png", data->folders + "/left/" + n + ".png",
                  fs::copy_options::overwrite_existing);
    fs::copy_file(kDir + "/right_img_" + n + ".png", data->folders + "/right/" + n + ".png",
                  fs::copy_options::overwrite_existing);
    data->left[i] = cv::imread(kDir + "/left_img_" + n + ".png", cv::IMREAD_GRAYSCALE);
    data->right[i] = cv::imread(kDir + "/right_img_" + n + ".png", cv::IMREAD_GRAYSCALE);
  }
  const std::string calibration = data->folders + "/calibration.yaml";
  openable::testing::WriteEurocCalibration(kDir, calibration);
  data->calibration = LoadStereoCalibration(calibration);
  data->rectifier = std::make_unique<StereoRectifier>(data->calibration, data->left[0].size());
  data->disparity = DisparityOptions::ForWidth(data->left[0].cols);
  return data.get();
}

// The four pairs as the pipeline reads them: each frame rectified, with its SGBM disparity.
std::unique_ptr<FrameSource> OpenPairs(const Data& d) {
  return OpenStereoFolders(d.folders + "/left", d.folders + "/right", "png", 0, -1, d.calibration);
}

int Hamming(const cv::Mat& a, const cv::Mat& b) {
  return static_cast<int>(cv::norm(a, b, cv::NORM_HAMMING));
}

void PrintDistances() {
  const Data* d = Load();
  if (d == nullptr) return;
  const auto source = OpenPairs(*d);
  std::printf("Hamming distances on the EuRoC pairs (0-1 revisit; 2-3 0.5 s apart):\n");
  std::printf("%-28s %5s %5s %5s %5s %5s %5s %6s\n", "setting", "0-1", "0-2", "0-3", "1-2", "1-3",
              "2-3", "bits");
  for (const char* name : {"LDB", "D-LDB"}) {
    for (const int bits : {256, 1386}) {
      for (const int grid : {1, 2}) {
        DescriptorOptions o;
        o.ldb_bits = bits;
        const auto descriptor = CreateDescriptor(name, o);
        const FrameDescriber describer(
            *descriptor, grid == 1 ? DescriptionType::kGlobal : DescriptionType::kGrid, grid, grid);
        const DescribedSequence seq = DescribeSequence(*source, describer, DescribeOptions{});
        char label[64];
        std::snprintf(label, sizeof label, "%s %s, %d bits", name,
                      grid == 1 ? "global" : "grid 2x2", bits);
        const cv::Mat& r = seq.rows;
        std::printf("%-28s %5d %5d %5d %5d %5d %5d %6d\n", label, Hamming(r.row(0), r.row(1)),
                    Hamming(r.row(0), r.row(2)), Hamming(r.row(0), r.row(3)),
                    Hamming(r.row(1), r.row(2)), Hamming(r.row(1), r.row(3)),
                    Hamming(r.row(2), r.row(3)), r.cols * 8);
      }
    }
  }
}

void BM_Rectify(benchmark::State& state) {
  const Data* d = Load();
  if (d == nullptr) return state.SkipWithError("dataset absent: ../shared/datasets");
  cv::Mat l, r;
  int i = 0;
  for (auto _ : state) {
    d->rectifier->Rectify(d->left[i % 4], d->right[i % 4], l, r);
    ++i;
  }
}
BENCHMARK(BM_Rectify)->Unit(benchmark::kMillisecond);

void BM_Sgbm(benchmark::State& state) {
  const Data* d = Load();
  if (d == nullptr) return state.SkipWithError("dataset absent: ../shared/datasets");
  cv::Mat l, r;
  d->rectifier->Rectify(d->left[0], d->right[0], l, r);
  for (auto _ : state) benchmark::DoNotOptimize(ComputeDisparity(l, r, d->disparity));
}
BENCHMARK(BM_Sgbm)->Unit(benchmark::kMillisecond);

void BM_DldbDescribe(benchmark::State& state) {
  const Data* d = Load();
  if (d == nullptr) return state.SkipWithError("dataset absent: ../shared/datasets");
  const auto source = OpenPairs(*d);
  const cv::Mat input = ToGrayDisparity8(source->Read(0));
  const auto dldb = CreateDescriptor("D-LDB", DescriptorOptions{});
  const FrameDescriber describer(*dldb, DescriptionType::kGlobal);
  cv::Mat row(1, describer.RowWidth(), CV_8U);
  for (auto _ : state) describer.Describe(input, row);
}
BENCHMARK(BM_DldbDescribe)->Unit(benchmark::kMillisecond);

// A whole frame as the pipeline reads it: decode both PNGs, rectify, SGBM, normalise.
void BM_StereoFrame(benchmark::State& state) {
  const Data* d = Load();
  if (d == nullptr) return state.SkipWithError("dataset absent: ../shared/datasets");
  const auto source = OpenPairs(*d);
  int i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(source->Read(i++ % 4));
}
BENCHMARK(BM_StereoFrame)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  PrintDistances();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
