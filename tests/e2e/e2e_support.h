// Helpers of the end-to-end tests: running a program, reading what it wrote.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "OpenABLE/io/json.h"
#include "tests/test_support.h"

namespace openable {
namespace e2e {

namespace fs = std::filesystem;

struct Outcome {
  int status = -1;
  std::string out, err;
};

inline std::string ReadAll(const std::string& path) { return testing::ReadBytes(path); }

inline std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// A bad command line: the arguments it adds to a good one, and the parts that the one line of
// its error must hold.
struct BadArgs {
  std::vector<std::string> args;
  std::vector<std::string> parts;
};

// Runs `exe` with `args` in `dir`; captures its exit status, stdout and stderr.
inline Outcome RunProgram(const std::string& exe, const std::vector<std::string>& args,
                          const std::string& dir) {
  std::string cmd = "cd " + ShellQuote(dir) + " && " + ShellQuote(exe);
  for (const auto& a : args) cmd += " " + ShellQuote(a);
  cmd += " >stdout.log 2>stderr.log";
  const int raw = std::system(cmd.c_str());
  Outcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128;
  o.out = ReadAll(dir + "/stdout.log");
  o.err = ReadAll(dir + "/stderr.log");
  fs::remove(dir + "/stdout.log");
  fs::remove(dir + "/stderr.log");
  return o;
}

// A run started in the background to be interrupted: `argv` (argv[0] looked up in PATH) runs
// in `dir` with `env` ("NAME=value") added, stdout discarded and stderr in `err`. Returns once
// stderr says "describing" (its first progress line, written when a traversal is described, as
// stderr is not a terminal) and 300 ms more, or after `wait_ms` without it; the test then
// checks the child is still running, signals it and reaps it. -1 when fork failed.
inline pid_t StartRunToInterrupt(const std::string& dir, const std::vector<std::string>& argv,
                                 const std::string& err, const std::vector<std::string>& env = {},
                                 int wait_ms = 4000) {
  const pid_t child = ::fork();
  if (child == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(99);
    ::dup2(::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), 2);
    ::dup2(::open("/dev/null", O_WRONLY), 1);
    for (const std::string& e : env) ::putenv(const_cast<char*>(e.c_str()));
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    ::_exit(98);
  }
  for (int k = 0;
       child > 0 && k < wait_ms / 10 && ReadAll(err).find("describing") == std::string::npos; ++k)
    ::usleep(10000);
  ::usleep(300000);
  return child;
}

// `first` (a Config.txt or a preset, when there is one), "--quiet", then each of `settings`
// ("Key=value") after --set: the arguments of a quiet run of Test_OpenABLE or openable_snaps.
inline std::vector<std::string> QuietArgs(const std::vector<std::string>& settings,
                                          const std::vector<std::string>& first = {}) {
  std::vector<std::string> args = first;
  args.push_back("--quiet");
  for (const std::string& setting : settings) args.insert(args.end(), {"--set", setting});
  return args;
}

// Runs Test_OpenABLE quietly in `dir` with each of `settings` ("Key=value") set.
inline Outcome RunTestOpenable(const std::string& dir, const std::vector<std::string>& settings) {
  return RunProgram(testing::TestOpenableExe(), QuietArgs(settings), dir);
}

// The settings of a loop-closure evaluation of KITTI 00 frames 0-1699 (the folder `kitti`) with
// sequences of `length` frames: loops from the poses (5 m in the ground plane, headings within
// 45 degrees, 100 frames apart), tolerance 3, the matrix m.npy and the evaluation "eval".
inline std::vector<std::string> Kitti00LoopSettings(const std::string& kitti, int length) {
  return {"Images_path=" + kitti + "/image_0",
          "Image_sequences=" + std::to_string(length),
          "Npy_name=m.npy",
          "Ground_truth_type=kitti",
          "Ground_truth=" + kitti + "/poses/00_first1700.txt",
          "Ground_truth_axes=xz",
          "Ground_truth_heading=45",
          "Exclusion=100",
          "Tolerance=3",
          "Evaluation_name=eval"};
}

// A writer of 64 x 32 colour MJPG frames at 10 frames a second to `path`; not opened when this
// OpenCV cannot write MJPG video.
inline cv::VideoWriter MjpgWriter(const std::string& path) {
  return cv::VideoWriter(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(64, 32));
}

// Independent .npy reader: float32, C order, 2-D.
inline cv::Mat1f ReadNpy(const std::string& path) {
  const std::string b = ReadAll(path);
  if (b.size() < 10 || b.compare(0, 6, "\x93NUMPY") != 0) return {};
  const size_t hl = static_cast<unsigned char>(b[8]) | (static_cast<unsigned char>(b[9]) << 8);
  const std::string header = b.substr(10, hl);
  if (header.find("'<f4'") == std::string::npos) return {};
  int rows = 0, cols = 0;
  if (std::sscanf(header.c_str() + header.find("'shape': (") + 10, "%d, %d", &rows, &cols) != 2)
    return {};
  cv::Mat1f m(rows, cols);
  if (b.size() != 10 + hl + static_cast<size_t>(rows) * cols * 4) return {};
  std::memcpy(m.data, b.data() + 10 + hl, static_cast<size_t>(rows) * cols * 4);
  return m;
}

// Share of query rows [q0, q0+n) whose smallest distance among reference columns
// [r0, r0+m) lies within `tol` frames of the aligned frame (frame-aligned traversals). Cells
// without a value (NaN in a saved .npy, +inf in memory) are never the smallest; a row without
// any value is a miss.
inline double AlignedRecallAt1(const cv::Mat1f& d, int q0, int r0, int n, int tol) {
  int hits = 0;
  for (int q = 0; q < n; ++q) {
    int best = -1;
    for (int r = 0; r < n; ++r) {
      const float v = d(q0 + q, r0 + r);
      if (std::isfinite(v) && (best < 0 || v < d(q0 + q, r0 + best))) best = r;
    }
    hits += best >= 0 && std::abs(best - q) <= tol;
  }
  return static_cast<double>(hits) / n;
}

// Brute force over two traversals of `n` frames each (references rows/columns 0..n-1, queries
// rows first_query..first_query+n-1): the queries whose best reference (smallest distance,
// lowest column on ties) has a ratio to the smallest distance more than `window` columns away
// (1 without such a rival, or when it is 0) of at most `threshold`, and, when `confirmed` is
// given, confirmed (Match_consistency: AgreeingByBruteForce). Cells without a value (NaN, +inf)
// are neither best matches nor rivals.
inline int AcceptedByRatio(const cv::Mat1f& m, int first_query, int n, int window, float threshold,
                           const std::vector<bool>* confirmed = nullptr) {
  int accepted = 0;
  for (int q = first_query; q < first_query + n; ++q) {
    if (confirmed != nullptr && !(*confirmed)[q - first_query]) continue;
    int best = -1;
    for (int c = 0; c < n; ++c)
      if (std::isfinite(m(q, c)) && (best < 0 || m(q, c) < m(q, best))) best = c;
    if (best < 0) continue;
    float rival = std::numeric_limits<float>::infinity();
    for (int c = 0; c < n; ++c)
      if (std::abs(c - best) > window && std::isfinite(m(q, c))) rival = std::min(rival, m(q, c));
    accepted += (std::isfinite(rival) && rival > 0 ? m(q, best) / rival : 1.0f) <= threshold;
  }
  return accepted;
}

// Per query of the query-reference block (rows first_query.., columns 0..references-1) of a
// written matrix, whether its best match is confirmed, from the rule of docs/evaluation.md
// written out here: the answer (smallest finite cell, lowest column on ties) of query q agrees
// when the answer of its partner (the nearest query at least max(L, 10) frames back whose
// window of frames is disjoint from q's, else the nearest such forward; windows q - L + 1 .. q,
// the first L - 1 queries 0 .. L - 1 with Sequence_partial ahead) differs from it by the
// queries between them within max(3, gap / 10).
inline std::vector<bool> AgreeingByBruteForce(const cv::Mat1f& m, int first_query, int queries,
                                              int references, int L, bool ahead = true) {
  std::vector<int> best(queries, -1);
  for (int q = 0; q < queries; ++q)
    for (int j = 0; j < references; ++j) {
      const float v = m(first_query + q, j);
      if (std::isfinite(v) && (best[q] < 0 || v < m(first_query + q, best[q]))) best[q] = j;
    }
  const auto window = [L, ahead](int q) {
    const int end = ahead && q < L - 1 ? L - 1 : q;
    return std::make_pair(std::max(0, end - L + 1), end);
  };
  const int gap = std::max(L, 10), tolerance = std::max(3, (gap + 5) / 10);
  std::vector<bool> out(queries, false);
  for (int q = 0; q < queries; ++q) {
    int partner = -1;
    for (int p = q - gap; p >= 0 && partner < 0; --p)
      if (window(p).second < window(q).first) partner = p;
    for (int p = q + gap; p < queries && partner < 0; ++p)
      if (window(p).first > window(q).second) partner = p;
    if (best[q] < 0 || partner < 0 || best[partner] < 0) continue;
    out[q] = std::abs((best[q] - best[partner]) - (q - partner)) <= tolerance;
  }
  return out;
}

// True when `s` is exactly one line.
inline bool OneLine(const std::string& s) {
  return !s.empty() && s.back() == '\n' && s.find('\n') == s.size() - 1;
}

// The JSON document in the file at `path`, parsed (nlohmann::json::parse throws, and so fails
// the test, when the file is absent or not JSON).
inline Json ReadJson(const std::string& path) { return Json::parse(ReadAll(path)); }

// A figure of an evaluated run (an element of "runs" in an evaluation or a sweep document,
// AddEvaluatedRunJson in OpenABLE/evaluation/report.cc): average_precision_percent from its
// "able_p", any other from its "per_query".
inline const Json& RunFigure(const Json& run, const std::string& key) {
  return key == "average_precision_percent" ? run.at("able_p").at(key)
                                            : run.at("per_query").at(key);
}

// Runs the reference on the matrix m.npy of a run in `dir` with `args` (the ground truth and
// the evaluation's settings; vicinity 7), prints the last line of its output, and fails the test
// when a figure of the run's eval.json differs by more than 5e-4.
inline void CheckAgainstReference(const std::string& dir, const std::vector<std::string>& args) {
  if (std::system("/usr/bin/python3 -c 'import numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 with numpy is absent (examples/setup.sh installs it)";
  std::vector<std::string> all = {testing::SourceDir() + "/tests/tools/evaluate_reference.py",
                                  "--matrix", "m.npy"};
  all.insert(all.end(), args.begin(), args.end());
  all.insert(all.end(), {"--vicinity", "7", "--compare", "eval.json"});
  const Outcome o = RunProgram("/usr/bin/python3", all, dir);
  EXPECT_EQ(o.status, 0) << o.out << o.err;
  std::cout << o.out.substr(o.out.rfind('\n', o.out.size() - 2) + 1);
}

// Runs Test_OpenABLE in a fresh temporary folder with `settings` (which name the matrix m.npy and
// the evaluation "eval"), prints its evaluation, and checks the figures against the reference
// run with `reference` (CheckAgainstReference). Returns the folder.
inline std::string EvaluateAgainstTheReference(const std::vector<std::string>& settings,
                                               const std::vector<std::string>& reference) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunTestOpenable(dir, settings);
  EXPECT_EQ(o.status, 0) << o.err;
  if (o.status != 0) return dir;
  std::cout << o.out.substr(o.out.find("Evaluation"));
  CheckAgainstReference(dir, reference);
  return dir;
}

}  // namespace e2e
}  // namespace openable
