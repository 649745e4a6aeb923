// Maps of millions of places: the index blocks of the online detector's map
// (matching/search/incremental_index.h) over N LDB rows of real frames, perturbed, then
// searched by real frames of another season. Prints the build time, the query time per frame
// (mean, 99th percentile), the agreement of each query's best candidate with the exact
// search over all N rows, and the memory per place beyond the descriptor row, with the CPU.
//
// The rows: LDB 256 bits (global, patch 64, the detector's defaults) of the Nordland trimmed
// summer frames (../shared/datasets), row i being frame i mod 1,788 with each bit flipped with
// probability --flip (default 0.05, about 13 of 256 bits), drawn with a fixed seed: places that
// repeat with small changes, as a route driven many times does, produced directly as rows so
// that no million files are needed. The queries: the winter frames' rows (the first --queries,
// default 500). A query agrees when its best candidate's distance equals the exact nearest
// distance (ties count).
//
// Then the map is saved as a map file (OpenABLE/online/map_file.h, the file SaveMap writes:
// its rows and the index blocks' saved forms) to --map-file (default a file in /tmp, removed
// after) and opened in place (memory-mapped, checksums verified in the background): from a
// cold page cache (the file's pages dropped first) and again warm, with the time to open, the
// first query and the next ones, and when the background check ended; then read into memory
// with every checksum verified first. Each time, whether the loaded map gives every query the
// same candidates as the map built.
//
// Usage: bench_map_scale [--rows N] [--engine binary_ivf|ivf|flann|hnsw] [--nprobe P]
//                        [--flip F] [--queries Q] [--datasets DIR] [--map-file PATH]
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/online/map_file.h"
#include "OpenABLE/online/online.h"
#include "matching/distances.h"
#include "matching/search/incremental_index.h"

namespace {

// Writes the file's pages to disk and drops them from the page cache, so that the next open
// reads from the disk (posix_fadvise; clean pages only, hence the fdatasync first).
void DropFromPageCache(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  fdatasync(fd);
  posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
  close(fd);
}

double Seconds(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

std::vector<cv::Mat> ReadFolder(const std::string& folder) {
  std::vector<cv::Mat> out;
  auto source = openable::OpenImageFolder(folder, "", 0, -1);
  for (int i = 0; i < source->Size(); ++i) out.push_back(source->Read(i));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int rows = 1000000, queries = 500, nprobe = 64;
  double flip = 0.05;
  std::string engine = "binary_ivf", datasets = OPENABLE_DATASETS_DIR;
  std::string map_file = "/tmp/bench_map_scale.map";
  bool keep_file = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--rows")
      rows = std::atoi(v.c_str());
    else if (a == "--engine")
      engine = v;
    else if (a == "--nprobe")
      nprobe = std::atoi(v.c_str());
    else if (a == "--flip")
      flip = std::atof(v.c_str());
    else if (a == "--queries")
      queries = std::atoi(v.c_str());
    else if (a == "--datasets")
      datasets = v;
    else if (a == "--map-file")
      map_file = v, keep_file = true;
    else {
      std::fprintf(stderr, "bench_map_scale: unknown argument %s (see the top of the source)\n",
                   a.c_str());
      return 1;
    }
  }
  openable::OnlineOptions options;  // LDB 256 bits, global, patch 64
  const cv::Mat summer =
      openable::DescribeImages(ReadFolder(datasets + "/nordland_trimmed/summer"), options);
  cv::Mat winter =
      openable::DescribeImages(ReadFolder(datasets + "/nordland_trimmed/winter"), options);
  queries = std::min(queries, winter.rows);
  winter = winter.rowRange(0, queries);

  // The map's rows: summer frames repeated, bits flipped.
  cv::Mat map(rows, summer.cols, CV_8U);
  std::mt19937_64 rng(17);
  const int bits = 8 * map.cols;
  std::binomial_distribution<int> flips(bits, flip);  // bits flipped in a row
  for (int i = 0; i < rows; ++i) {
    summer.row(i % summer.rows).copyTo(map.row(i));
    std::uint8_t* r = map.ptr<std::uint8_t>(i);
    for (int f = flips(rng); f > 0; --f) {  // a bit drawn twice flips back: rare, harmless
      const int bit = static_cast<int>(rng() % static_cast<std::uint64_t>(bits));
      r[bit / 8] = static_cast<std::uint8_t>(r[bit / 8] ^ (1u << (bit % 8)));
    }
  }

  openable::IncrementalIndexOptions index_options;
  index_options.approximate.engine = engine;
  index_options.approximate.nprobe = nprobe;
  index_options.approximate.k = 5;
  index_options.background_merges = false;
  openable::IncrementalIndex index(map.cols, CV_8U, index_options);
  auto t = std::chrono::steady_clock::now();
  index.Reserve(rows);
  for (int i = 0; i < rows; ++i) index.Append(map.row(i));
  index.Update(rows, /*background=*/false);
  const double build = Seconds(t);

  // Queries: each frame's candidates, the best by exact distance.
  std::vector<double> times;
  std::vector<float> best(static_cast<std::size_t>(queries));
  const cv::Mat stored = index.Rows();
  double searching = 0;
  std::size_t scored = 0;
  for (int q = 0; q < queries; ++q) {
    t = std::chrono::steady_clock::now();
    bool approximate = false;
    const std::vector<int> candidates = index.Candidates(winter.row(q), rows, &approximate);
    searching += Seconds(t);
    scored += candidates.size();
    float d = 1e30f;
    for (const int j : candidates) d = std::min(d, openable::RowDistance(stored, j, winter, q));
    best[static_cast<std::size_t>(q)] = d;
    times.push_back(Seconds(t));
  }
  // Exact: every row.
  const openable::HammingReferences all(map);
  std::vector<float> distances(static_cast<std::size_t>(rows));
  int agree = 0;
  for (int q = 0; q < queries; ++q) {
    all.Distances(winter.ptr<std::uint8_t>(q), distances.data());
    const float exact = *std::min_element(distances.begin(), distances.end());
    agree += best[static_cast<std::size_t>(q)] == exact;
  }
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  double mean = 0;
  for (const double s : times) mean += s;
  mean /= std::max<std::size_t>(1, times.size());
  const double p99 = sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
  const double beyond = static_cast<double>(index.MemoryBytes()) / rows - map.cols;
  std::printf("CPU: %s\n", CpuModel().c_str());
  std::printf(
      "%d rows of %d bytes (Nordland summer LDB, bits flipped with p = %.3f), engine %s, "
      "nprobe %d, %d blocks\n",
      rows, map.cols, flip, engine.c_str(), nprobe, index.Blocks());
  std::printf(
      "  build %.1f s; query mean %.3f ms, p99 %.3f ms (%d winter frames); best "
      "candidate = exact nearest for %.3f of them; memory %.1f bytes a place beyond "
      "the %d-byte row\n",
      build, 1e3 * mean, 1e3 * p99, queries, static_cast<double>(agree) / queries, beyond,
      map.cols);
  std::printf(
      "  of a query: %.3f ms in the blocks' search, the rest scoring %.0f candidates "
      "(the blocks' k best and the rows not in a block yet)\n",
      1e3 * searching / queries, static_cast<double>(scored) / queries);

  // Saved and loaded as a map file: opened in place (mapped, checksums verified in the
  // background), from a cold page cache and again warm, then read into memory.
  t = std::chrono::steady_clock::now();
  openable::MapFile file;
  file.settings = {{"frames", std::to_string(rows)},
                   {"row_width", std::to_string(map.cols)},
                   {"row_type", "CV_8U"},
                   {"engine", engine}};
  file.sessions = {{"bench", "", 0, rows}};
  file.rows = stored;
  file.blocks = index.SaveBlocks();
  openable::WriteMapFile(map_file, file);
  const double save = Seconds(t);
  std::ifstream sized(map_file, std::ios::binary | std::ios::ate);
  const double megabytes = static_cast<double>(sized.tellg()) / 1e6;
  file = openable::MapFile();
  const auto same_candidates = [&](const openable::IncrementalIndex& loaded) {
    int same = 0;
    for (int q = 0; q < queries; ++q) {
      bool a = false, b = false;
      same +=
          index.Candidates(winter.row(q), rows, &a) == loaded.Candidates(winter.row(q), rows, &b);
    }
    return same;
  };
  for (const bool cold : {true, false}) {
    if (cold) DropFromPageCache(map_file);
    const auto opening = std::chrono::steady_clock::now();
    t = opening;
    openable::MapFile read = openable::ReadMapFile(map_file);
    openable::IncrementalIndex loaded(map.cols, CV_8U, index_options);
    loaded.Restore(read.rows, read.blocks, read.mapping);
    const double open = Seconds(t);
    t = std::chrono::steady_clock::now();
    bool approximate = false;
    loaded.Candidates(winter.row(0), rows, &approximate);
    const double first = Seconds(t);
    t = std::chrono::steady_clock::now();
    for (int q = 1; q < queries; ++q) loaded.Candidates(winter.row(q), rows, &approximate);
    const double rest = Seconds(t) / std::max(1, queries - 1);
    const std::string error = read.check.get();
    const double checked = Seconds(opening);
    // The first frame added after opening copies the rows out of the file (the buffer then
    // grows by doubling, as the detector's always does).
    t = std::chrono::steady_clock::now();
    if (!cold) loaded.Append(winter.row(0));
    const double append = Seconds(t);
    if (!cold)
      std::printf(
          "  the first row appended after opening in place: %.2f s (the rows copied "
          "out of the file)\n",
          append);
    std::printf(
        "  opened in place (%s page cache) in %.3f s; first query %.1f ms, then %.3f ms "
        "a query; checksums verified by %.1f s after opening, while the queries ran (%s); the "
        "same candidates "
        "as the map built for %d of %d queries\n",
        cold ? "cold" : "warm", open, 1e3 * first, 1e3 * rest, checked,
        error.empty() ? "match" : error.c_str(), same_candidates(loaded), queries);
  }
  t = std::chrono::steady_clock::now();
  openable::MapReadOptions copy;
  copy.in_place = false;
  copy.check_in_background = false;
  const openable::MapFile read = openable::ReadMapFile(map_file, copy);
  openable::IncrementalIndex loaded(map.cols, CV_8U, index_options);
  loaded.Restore(read.rows, read.blocks);
  const double load = Seconds(t);
  const int same = same_candidates(loaded);
  if (!keep_file) std::remove(map_file.c_str());
  std::printf(
      "  saved in %.1f s (%.0f MB); read into memory in %.1f s (checksums first, rows "
      "and blocks copied); the same candidates for %d of %d queries\n",
      save, megabytes, load, same, queries);
  return 0;
}
