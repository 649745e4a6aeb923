// Writes the seeds of the map fuzzer that OpenABLE writes itself (tests/fuzz/corpus/map/):
// small saved maps of the detectors of tests/fuzz/map_detectors.h.
//   build_fuzz/tests/fuzz/write_seeds tests/fuzz/corpus
// The other seeds are written by hand or by NumPy (docs/robustness.md, "Fuzz targets").
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <opencv2/core.hpp>

#include "OpenABLE/online/online.h"
#include "tests/fuzz/map_detectors.h"

namespace {

using openable::OnlineDetector;
using openable::fuzz::MapDetectorOptions;
using openable::fuzz::MapFrame;
using openable::fuzz::MapKind;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// ---- Maps

void WriteMaps(const std::string& dir) {
  cv::RNG rng(7);
  {  // 40 LDB rows: 38 searchable, one index block of 32 rows.
    OnlineDetector d(MapDetectorOptions(MapKind::kRows));
    cv::Mat row(1, d.RowWidth(), d.RowType());
    for (int i = 0; i < 40; ++i) {
      rng.fill(row, cv::RNG::UNIFORM, 0, 256);
      d.AddDescriptor(row);
    }
    d.SaveMap(dir + "/rows.map");
    // The same map cut short, and with one byte of its rows changed (checksum wrong).
    const std::string bytes = ReadFile(dir + "/rows.map");
    WriteFile(dir + "/rows_truncated.map", bytes.substr(0, bytes.size() / 2));
    std::string flipped = bytes;
    flipped[bytes.size() - 100] ^= 0x20;
    WriteFile(dir + "/rows_flipped.map", flipped);
  }
  {  // 6 HOG rows (36 floats).
    OnlineDetector d(MapDetectorOptions(MapKind::kFloat));
    cv::Mat row(1, d.RowWidth(), d.RowType());
    for (int i = 0; i < 6; ++i) {
      rng.fill(row, cv::RNG::UNIFORM, 0.0, 1.0);
      d.AddDescriptor(row);
    }
    d.SaveMap(dir + "/float.map");
  }
  {  // 3 frames with their ORB features.
    OnlineDetector d(MapDetectorOptions(MapKind::kVerifying));
    for (int i = 0; i < 3; ++i) d.AddFrame(MapFrame(i));
    d.SaveMap(dir + "/verifying.map");
  }
  {  // An empty map.
    OnlineDetector d(MapDetectorOptions(MapKind::kRows));
    d.SaveMap(dir + "/empty.map");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_FOLDER (writes CORPUS_FOLDER/map)\n", argv[0]);
    return 2;
  }
  const std::string corpus = argv[1];
  std::filesystem::create_directories(corpus + "/map");
  WriteMaps(corpus + "/map");
  return 0;
}
