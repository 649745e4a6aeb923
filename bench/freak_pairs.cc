// Selects FREAK's 512 pairs as the FREAK paper does (Alahi et al., CVPR 2012, Section 4.3),
// on whole frames of ../shared/datasets resized to the 64 x 64 patch, and prints the table
// kept in descriptors/freak.cc. Run once offline; rerun to check the table:
//
//   build/bench/freak_pairs [datasets_dir]          prints the table
//   build/bench/freak_pairs --check [datasets_dir]  exit 0 when it equals FreakPairs()
//
// Training frames: every frame of KITTI 00 (kitti00_first1700/image_0, 1700), Nordland
// (nordland_trimmed/summer and winter, 1788 + 1788) and Gardens Point (gardens_point/day_left
// and day_right, 200 + 200), read as grey (cv::IMREAD_GRAYSCALE) and resized to 64 x 64 with
// cv::INTER_AREA. For each frame, the 903 tests of FreakDescriptor::AllPairBits.
//
// Selection, with exact integer counts:
//  1. p_c = mean of test c over the frames; tests with p_c = 0 or 1 are dropped;
//  2. the tests are ordered by |p_c - 0.5| (ties: lower test index first);
//  3. for a threshold t, walk that order and keep a test when its |Pearson correlation| with
//     every test kept so far is below t;
//  4. t starts at 0.05 and rises by 0.005 until at least 512 tests are kept; the first 512
//     kept, in the order kept, are the table (bit k = k-th kept).
#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "descriptors/freak.h"

namespace fs = std::filesystem;
using openable::kFreakAllPairs;
using openable::kFreakBits;
using openable::kFreakFields;

namespace {

std::vector<fs::path> SortedFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  bool check = false;
  std::string datasets = OPENABLE_DATASETS_DIR;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--check") {
      check = true;
    } else {
      datasets = a;
    }
  }
  const std::vector<std::string> folders = {"kitti00_first1700/image_0", "nordland_trimmed/summer",
                                            "nordland_trimmed/winter", "gardens_point/day_left",
                                            "gardens_point/day_right"};

  openable::DescriptorOptions options;
  options.patch_size = 64;
  const openable::FreakDescriptor freak(options);

  // Column c of the test matrix as a bit set over frames.
  std::vector<std::vector<std::uint64_t>> columns(kFreakAllPairs);
  std::size_t frames = 0;
  for (const std::string& folder : folders) {
    const fs::path dir = fs::path(datasets) / folder;
    if (!fs::is_directory(dir)) {
      std::cerr << "freak_pairs: " << dir << " not found\n";
      return 1;
    }
    for (const fs::path& file : SortedFiles(dir)) {
      const cv::Mat grey = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
      if (grey.empty()) {
        std::cerr << "freak_pairs: cannot read " << file << "\n";
        return 1;
      }
      cv::Mat patch;
      cv::resize(grey, patch, cv::Size(64, 64), 0, 0, cv::INTER_AREA);
      const std::vector<std::uint8_t> bits = freak.AllPairBits(patch);
      if (frames % 64 == 0) {
        for (auto& c : columns) c.push_back(0);
      }
      for (int c = 0; c < kFreakAllPairs; ++c) {
        if (bits[c]) columns[c][frames / 64] |= std::uint64_t{1} << (frames % 64);
      }
      ++frames;
    }
  }

  const auto popcount = [](const std::vector<std::uint64_t>& a,
                           const std::vector<std::uint64_t>* b) {
    long long n = 0;
    for (std::size_t w = 0; w < a.size(); ++w) {
      n += static_cast<long long>(std::bitset<64>(b ? (a[w] & (*b)[w]) : a[w]).count());
    }
    return n;
  };
  std::vector<long long> ones(kFreakAllPairs);
  for (int c = 0; c < kFreakAllPairs; ++c) ones[c] = popcount(columns[c], nullptr);

  const double n = static_cast<double>(frames);
  std::vector<int> order;
  for (int c = 0; c < kFreakAllPairs; ++c) {
    if (ones[c] > 0 && ones[c] < static_cast<long long>(frames)) order.push_back(c);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return std::abs(ones[a] / n - 0.5) < std::abs(ones[b] / n - 0.5);
  });

  // |correlation| between any two candidate tests, from exact co-occurrence counts.
  std::vector<double> corr(static_cast<std::size_t>(kFreakAllPairs) * kFreakAllPairs, 0.0);
  for (std::size_t ia = 0; ia < order.size(); ++ia) {
    const int a = order[ia];
    for (std::size_t ib = ia + 1; ib < order.size(); ++ib) {
      const int b = order[ib];
      const double pa = ones[a] / n, pb = ones[b] / n;
      const double pab = popcount(columns[a], &columns[b]) / n;
      const double r = std::abs(pab - pa * pb) / std::sqrt(pa * (1 - pa) * pb * (1 - pb));
      corr[static_cast<std::size_t>(a) * kFreakAllPairs + b] = r;
      corr[static_cast<std::size_t>(b) * kFreakAllPairs + a] = r;
    }
  }

  std::vector<int> kept;
  double threshold = 0.05;
  for (int step = 0;; ++step) {
    threshold = 0.05 + 0.005 * step;
    kept.clear();
    for (const int c : order) {
      bool ok = true;
      for (const int k : kept) {
        if (corr[static_cast<std::size_t>(c) * kFreakAllPairs + k] >= threshold) {
          ok = false;
          break;
        }
      }
      if (ok) kept.push_back(c);
    }
    if (kept.size() >= static_cast<std::size_t>(kFreakBits) || threshold > 1.0) break;
  }
  if (kept.size() < static_cast<std::size_t>(kFreakBits)) {
    std::cerr << "freak_pairs: only " << kept.size() << " usable tests\n";
    return 1;
  }
  kept.resize(kFreakBits);

  // Test index -> pair (i, j).
  std::vector<std::array<int, 2>> pair_of;
  for (int i = 0; i < kFreakFields; ++i)
    for (int j = i + 1; j < kFreakFields; ++j) pair_of.push_back({i, j});

  if (check) {
    const auto& table = openable::FreakPairs();
    for (int k = 0; k < kFreakBits; ++k) {
      if (table[k][0] != pair_of[kept[k]][0] || table[k][1] != pair_of[kept[k]][1]) {
        std::cerr << "freak_pairs: the table of descriptors/freak.cc differs at bit " << k << "\n";
        return 1;
      }
    }
    std::cout << "freak_pairs: the table matches (" << frames << " frames, threshold " << threshold
              << ")\n";
    return 0;
  }

  double worst = 0.0;
  for (std::size_t a = 0; a < kept.size(); ++a)
    for (std::size_t b = a + 1; b < kept.size(); ++b)
      worst = std::max(worst, corr[static_cast<std::size_t>(kept[a]) * kFreakAllPairs + kept[b]]);
  std::printf(
      "// %zu frames, %zu candidate tests, threshold %.3f, largest |correlation| kept "
      "%.3f, means of the first and last kept bits %.3f, %.3f\n",
      frames, order.size(), threshold, worst, ones[kept.front()] / n, ones[kept.back()] / n);
  for (int k = 0; k < kFreakBits; ++k) {
    std::printf("%s{%d, %d},", k % 8 == 0 ? "    " : " ", pair_of[kept[k]][0], pair_of[kept[k]][1]);
    if (k % 8 == 7) std::printf("\n");
  }
  return 0;
}
