// The online detector (OpenABLE/online/online.h) frame by frame on KITTI 00 frames 0-1699
// (../shared/datasets/kitti00_first1700): per-frame latency of description and search (mean,
// median, 99th percentile, maximum; image decoding is not counted), and the loops it accepts
// against loop_gt_5m.txt, with a threshold sweep of its top-1 candidates.
//
// Usage: bench_online [--datasets DIR] [--descriptor LDB] [--sequence L] [--exclusion E]
//                     [--threshold T] [--score distance|ratio] [--score-window W]
//                     [--consistency N]
//                     [--heading-limit DEG] [--prefill N] [--exact-limit N]
//                     [--block-frames N] [--foreground-merges] [--csv FILE]
//                     [--verify] [--verify-candidates K] [--verify-consistency N]
//                     [--verify-features ORB|SIFT] [--verify-max-features N]
//                     [--engine NAME] [--save-map FILE]
// --engine NAME: an approximate-search engine of matching/search/engine_registry.h (default auto).
// --verify turns geometric verification on (OnlineOptions::verification, tolerance 3 frames):
// the answer of a frame is then its first verified candidate, and the time of the checks is
// reported apart ("verify": features of the frame and every candidate's check).
// --save-map FILE saves the map at the end (OnlineDetector::SaveMap), loads it into a new
// detector, and builds the same map from the rows (AddToMap) for comparison: the times of the
// three and the file's size.
// --prefill N adds N random rows before the frames (a map of N + 1700 frames, for the latency
// of large maps only: random rows are never loop candidates of real frames in practice).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/progress.h"  // SecondsSince
#include "OpenABLE/online/online.h"

namespace {

struct Stats {
  double mean = 0, p50 = 0, p99 = 0, max = 0;
};

Stats Summarise(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  for (double x : v) s.mean += x;
  s.mean /= v.size();
  auto at = [&](double p) {
    return v[std::min(v.size() - 1, static_cast<size_t>(std::ceil(p * v.size())) - 1)];
  };
  s.p50 = at(0.5);
  s.p99 = at(0.99);
  s.max = v.back();
  return s;
}

void Print(const char* what, const Stats& s) {
  std::printf("  %-22s mean %7.3f ms  median %7.3f ms  p99 %7.3f ms  max %7.3f ms\n", what,
              1e3 * s.mean, 1e3 * s.p50, 1e3 * s.p99, 1e3 * s.max);
}

}  // namespace

int main(int argc, char** argv) {
  std::string datasets = OPENABLE_DATASETS_DIR, csv, save_map;
  openable::OnlineOptions options;
  double heading_limit = -1;
  int prefill = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_online: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--datasets")
      datasets = next();
    else if (a == "--descriptor")
      options.descriptor.name = next();
    else if (a == "--sequence")
      options.sequence_length = std::stoi(next());
    else if (a == "--exclusion")
      options.exclusion = std::stoi(next());
    else if (a == "--threshold")
      options.threshold = std::stod(next());
    else if (a == "--consistency")
      options.consistency = std::stoi(next());
    else if (a == "--score")
      options.score.kind = openable::ParseEnum<openable::MatchScore>(next(), "--score");
    else if (a == "--score-window")
      options.score.window = std::stoi(next());
    else if (a == "--heading-limit")
      heading_limit = std::stod(next());
    else if (a == "--prefill")
      prefill = std::stoi(next());
    else if (a == "--exact-limit")
      options.exact_limit = std::stoi(next());
    else if (a == "--block-frames")
      options.block_frames = std::stoi(next());
    else if (a == "--foreground-merges")
      options.background_merges = false;
    else if (a == "--csv")
      csv = next();
    else if (a == "--engine")
      options.approximate.engine = openable::ParseApproximateEngine(next(), "--engine");
    else if (a == "--save-map")
      save_map = next();
    else if (a == "--verify")
      options.verification.enabled = true;
    else if (a == "--verify-candidates")
      options.verification.candidates = std::stoi(next());
    else if (a == "--verify-consistency")
      options.verification.consistency = std::stoi(next());
    else if (a == "--verify-features")
      options.verification.features =
          openable::ParseEnum<openable::LocalFeatures>(next(), "--verify-features");
    else if (a == "--verify-max-features")
      options.verification.max_features = std::stoi(next());
    else {
      std::fprintf(stderr,
                   "bench_online: unknown argument %s (see the comment at the top of "
                   "bench/bench_online.cc)\n",
                   a.c_str());
      return 2;
    }
  }
  const std::string dir = datasets + "/kitti00_first1700";
  if (!std::filesystem::exists(dir + "/image_0")) {
    std::printf("bench_online: %s/image_0 absent, nothing measured\n", dir.c_str());
    return 0;
  }
  // Ground truth: pairs (query, earlier) within 5 m, optionally with a heading limit.
  std::set<std::pair<int, int>> truth;
  std::vector<char> positive(1700, 0);
  {
    std::ifstream in(dir + "/loop_gt_5m.txt");
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream s(line);
      int q, j;
      double d, heading;
      if (!(s >> q >> j >> d >> heading)) continue;
      if (heading_limit >= 0 && heading > heading_limit) continue;
      truth.insert({q, j});
      if (q < 1700) positive[q] = 1;
    }
  }
  options.verification.tolerance = 3;
  if (options.verification.enabled)
    options.approximate.k = std::max(options.approximate.k, options.verification.candidates);
  try {
    openable::OnlineDetector detector(options);
    if (prefill > 0) {
      cv::RNG rng(1);
      cv::Mat rows(prefill, detector.RowWidth(), detector.RowType());
      if (detector.RowType() == CV_8U)
        rng.fill(rows, cv::RNG::UNIFORM, 0, 256);
      else
        rng.fill(rows, cv::RNG::UNIFORM, 0.0, 0.2);
      const auto start = std::chrono::steady_clock::now();
      detector.AddToMap(rows);
      std::printf("map of %d random rows added in %.2f s\n", prefill,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::vector<double> describe, search, verify, total;
    std::vector<std::pair<double, int>> top;  // (normalised, correct) of each query's best
    int accepted = 0, accepted_correct = 0, approximate_frames = 0;
    std::ofstream out;
    if (!csv.empty()) {
      out.open(csv);
      out << "frame,best,distance,normalized,accepted,correct,positive,describe_ms,search_ms\n";
    }
    for (int f = 0; f < 1700; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "/image_0/%06d.png", f);
      const cv::Mat image = cv::imread(dir + name, cv::IMREAD_GRAYSCALE);
      if (image.empty()) {
        std::fprintf(stderr, "bench_online: cannot read %s%s\n", dir.c_str(), name);
        return 1;
      }
      const openable::OnlineResult r = detector.AddFrame(image);
      describe.push_back(r.describe_seconds);
      search.push_back(r.search_seconds);
      verify.push_back(r.verify_seconds);
      total.push_back(r.describe_seconds + r.search_seconds + r.verify_seconds);
      approximate_frames += r.approximate;
      if (r.candidates.empty()) continue;
      // The frame's answer: its best candidate, or with verification its first verified one.
      std::size_t answer = 0;
      if (options.verification.enabled) {
        while (answer < r.candidates.size() && !r.candidates[answer].verified) ++answer;
        if (answer == r.candidates.size()) continue;  // no verified candidate: no answer
      }
      const auto& c = r.candidates[answer];
      const int best = c.frame - prefill;  // frame number in KITTI (< 0: a random row)
      // Right within 2 frames of a ground-truth pair (docs/evaluation.md, Tolerance 2).
      bool correct = false;
      for (int d = -2; d <= 2 && !correct; ++d) correct = truth.count({f, best + d}) > 0;
      top.emplace_back(c.score, correct);  // the normalised distance, or the ratio
      if (c.accepted) ++accepted, accepted_correct += correct;
      if (out)
        out << f << ',' << best << ',' << c.distance << ',' << c.normalized << ',' << c.accepted
            << ',' << correct << ',' << int(positive[f]) << ',' << 1e3 * r.describe_seconds << ','
            << 1e3 * r.search_seconds << '\n';
    }
    const int positives = std::count(positive.begin(), positive.end(), 1);
    std::printf(
        "OnlineDetector on KITTI 00 frames 0-1699: %s, L=%d, exclusion %d, score %s, "
        "threshold %.3f, consistency %d, %d random rows before (map %d frames at the end), exact "
        "limit %d, %d "
        "frames searched with %s index blocks (%d blocks at the end, merges %s), memory "
        "%.1f MB\n",
        options.descriptor.name.c_str(), options.sequence_length, options.exclusion,
        openable::EnumName(options.score.kind).c_str(), options.Threshold(), options.consistency,
        prefill, detector.Size(), options.exact_limit, approximate_frames,
        options.approximate.engine.c_str(), detector.Blocks(),
        options.background_merges ? "in the background" : "in AddFrame",
        detector.MemoryBytes() / 1e6);
    Print("describe", Summarise(describe));
    Print("search", Summarise(search));
    if (options.verification.enabled) {
      std::printf("  verification: %s, %d features, %d candidates, consistency %d\n",
                  openable::EnumName(options.verification.features).c_str(),
                  options.verification.max_features, options.verification.candidates,
                  options.verification.consistency);
      Print("verify", Summarise(verify));
    }
    Print("whole frame", Summarise(total));
    std::printf("  ground truth: %d frames with a loop (5 m%s)\n", positives,
                heading_limit >= 0
                    ? (", heading <= " + std::to_string(heading_limit) + " deg").c_str()
                    : ", any heading");
    std::printf("  accepted at %.3f: %d frames, %d right (precision %.3f), recall %.3f\n",
                options.Threshold(), accepted, accepted_correct,
                accepted ? double(accepted_correct) / accepted : 1.0,
                positives ? double(accepted_correct) / positives : 0.0);
    // Sweep: accepting the top-1 candidate when its score (--score) <= t.
    std::sort(top.begin(), top.end());
    double best_f1 = 0, best_t = 0, r100 = 0, t100 = 0;
    int tp = 0, fp = 0;
    for (size_t i = 0; i < top.size(); ++i) {
      top[i].second ? ++tp : ++fp;
      if (i + 1 < top.size() && top[i + 1].first == top[i].first) continue;
      const double p = double(tp) / (tp + fp), rc = positives ? double(tp) / positives : 0;
      const double f1 = p + rc > 0 ? 2 * p * rc / (p + rc) : 0;
      if (f1 > best_f1) best_f1 = f1, best_t = top[i].first;
      if (fp == 0) r100 = rc, t100 = top[i].first;
    }
    std::printf(
        "  sweep of the top-1 threshold: max F1 %.3f at %.4f; recall at precision 1: "
        "%.3f up to %.4f\n",
        best_f1, best_t, r100, t100);
    if (!save_map.empty()) {
      using Clock = std::chrono::steady_clock;
      auto start = Clock::now();
      detector.SaveMap(save_map);
      const double save = openable::SecondsSince(start);
      openable::OnlineDetector loaded(options);
      start = Clock::now();
      const auto info = loaded.LoadMap(save_map);
      const double load = openable::SecondsSince(start);
      openable::OnlineDetector rebuilt(options);
      start = Clock::now();
      rebuilt.AddToMap(detector.Descriptors());
      const double build = openable::SecondsSince(start);
      std::printf(
          "  saved map: %d frames, %d blocks, %.1f MB; save %.2f s, load %.2f s "
          "(blocks %s), the same map built from its rows %.2f s\n",
          info.frames, info.blocks, std::filesystem::file_size(save_map) / 1e6, save, load,
          info.rebuilt ? "rebuilt" : "read", build);
    }
  } catch (const openable::InputError& e) {
    std::fprintf(stderr, "bench_online: %s\n", e.what());
    return 1;
  }
  return 0;
}
