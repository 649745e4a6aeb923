// The online detector (OpenABLE/online/online.h) against the batch matrix and against an
// independent brute force on real KITTI frames: single-frame distances counted bit by bit here,
// sequence sums written from their definition (matching/sequence.h), candidates as the k smallest
// with ties to the earlier frame.
#include "OpenABLE/online/online.h"

#include <gtest/gtest.h>

#include <bitset>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "matching/bounded.h"
#include "tests/online/index_engines.h"
#include "tests/test_frames.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using testing::ExpectInputError;

using testing::Kitti00LeftDir;
using testing::ReadKitti00Frames;

// Brute force: D(a, b) bit by bit (CV_8U rows) or Euclidean in double (CV_32F rows).
double Single(const cv::Mat& rows, int a, int b) {
  double s = 0;
  for (int k = 0; k < rows.cols; ++k) {
    if (rows.type() == CV_8U) {
      s += std::bitset<8>(rows.at<uchar>(a, k) ^ rows.at<uchar>(b, k)).count();
    } else {
      const double d = double(rows.at<float>(a, k)) - rows.at<float>(b, k);
      s += d * d;
    }
  }
  return rows.type() == CV_8U ? s : std::sqrt(s);
}

// S(q, j) from its definition: the c = min(L, q + 1, j + 1) existing terms, times L / c.
double Sequence(const cv::Mat& rows, int q, int j, int L) {
  const int c = std::min({L, q + 1, j + 1});
  double s = 0;
  for (int k = 0; k < c; ++k) s += Single(rows, q - k, j - k);
  return s * L / c;
}

struct Expected {
  int frame;
  double distance;
};

// The k best earlier frames j <= q - exclusion of frame q, ties to the earlier frame.
std::vector<Expected> BruteForce(const cv::Mat& rows, int q, int L, int exclusion, int k) {
  std::vector<std::pair<double, int>> all;
  for (int j = 0; j <= q - exclusion; ++j) all.emplace_back(Sequence(rows, q, j, L), j);
  std::sort(all.begin(), all.end());
  std::vector<Expected> out;
  for (int i = 0; i < std::min<int>(k, all.size()); ++i)
    out.push_back({all[i].second, all[i].first});
  return out;
}

TEST(OnlineDetector, GivesTheBruteForceCandidatesOnRealKittiFrames) {
  OPENABLE_REQUIRE_PATH(Kitti00LeftDir());
  // Every 4th frame of 0-1699: the loop of frames 1559-1641 revisits the start of the route.
  const std::vector<cv::Mat> frames = ReadKitti00Frames(4, 1699);
  OnlineOptions options;
  options.sequence_length = 5;
  options.exclusion = 25;
  options.candidates = 4;
  options.consistency = 0;  // the score alone (the confirmation: tests/online/map_tuning_test.cc)
  OnlineDetector detector(options);
  const cv::Mat batch_rows = DescribeImages(frames, options);
  // The batch path of Test_OpenABLE: the normalised sequence matrix and its kept matches (the
  // k best of each query among frames at least `exclusion` earlier), with Sequence_partial
  // scale, the rule of a detector that has not seen the frames after its query yet.
  float max_distance = 0;
  const cv::Mat1f matrix = DistanceMatrix(batch_rows, 5, SequenceDirection::kForward, {}, 0,
                                          &max_distance, {}, SequencePartial::kScale);
  const int n = static_cast<int>(frames.size());
  KeepRules rules;
  rules.best = 4;
  rules.exclusion = 25;
  const std::vector<Match> batch = MatchesFromMatrix(matrix, MatchBlock{0, n, 0, n, true}, rules);
  std::vector<std::vector<Match>> batch_of(frames.size());
  for (const Match& m : batch) batch_of[m.query].push_back(m);
  int accepted_loops = 0, compared = 0;
  for (int q = 0; q < static_cast<int>(frames.size()); ++q) {
    const OnlineResult r = detector.AddFrame(frames[q]);
    ASSERT_EQ(r.frame, q);
    EXPECT_FALSE(r.approximate);
    // The stored row is the batch row (same description of the same image).
    ASSERT_EQ(cv::norm(detector.Descriptors().row(q), batch_rows.row(q), cv::NORM_HAMMING), 0);
    const std::vector<Expected> want = BruteForce(batch_rows, q, 5, 25, 4);
    ASSERT_EQ(r.candidates.size(), want.size()) << "frame " << q;
    for (size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(r.candidates[i].frame, want[i].frame) << "frame " << q << " rank " << i;
      // Sums are rounded to float as in the batch matrix (matching/sequence.cc).
      const double distance = static_cast<float>(want[i].distance);
      EXPECT_EQ(r.candidates[i].distance, distance);
      // Hamming: normalised = mean fraction of differing bits over the L frames.
      EXPECT_DOUBLE_EQ(r.candidates[i].normalized, distance / (5.0 * 256));
      EXPECT_EQ(r.candidates[i].accepted, r.candidates[i].normalized <= options.Threshold());
      // The same candidates as the batch matrix, whose cells are S / max(S).
      ASSERT_EQ(batch_of[q].size(), want.size()) << "frame " << q;
      EXPECT_EQ(batch_of[q][i].reference, r.candidates[i].frame) << "frame " << q;
      EXPECT_NEAR(batch_of[q][i].distance * max_distance, r.candidates[i].distance, 1e-3);
      ++compared;
    }
    // Accepted candidates in the loop: KITTI frames 1559-1641 revisit frames ~0-200.
    if (!r.candidates.empty() && r.candidates[0].accepted && q * 4 >= 1570 && q * 4 <= 1630 &&
        r.candidates[0].frame * 4 < 300)
      ++accepted_loops;
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(accepted_loops, 5) << "the default threshold should accept the real loop";
  EXPECT_EQ(detector.Size(), static_cast<int>(frames.size()));
  // Memory: the rows only (exact search), in a buffer at most twice the rows.
  EXPECT_LE(detector.MemoryBytes(), 2 * 32 * static_cast<std::int64_t>(frames.size()) + 64 * 32);
  EXPECT_EQ(detector.Blocks(), 0);
}

TEST(OnlineDetector, FloatDescriptorsMatchTheBruteForceToo) {
  OPENABLE_REQUIRE_PATH(Kitti00LeftDir());
  const std::vector<cv::Mat> frames = ReadKitti00Frames(20, 1699);
  OnlineOptions options;
  options.descriptor.name = "HOG";
  options.sequence_length = 3;
  options.exclusion = 5;
  options.candidates = 3;
  OnlineDetector detector(options);
  const cv::Mat rows = DescribeImages(frames, options);
  ASSERT_EQ(rows.type(), CV_32F);
  double largest = 0;
  for (int q = 0; q < rows.rows; ++q) {
    const OnlineResult r = detector.AddFrame(frames[q]);
    for (int j = 0; j <= q - 5; ++j)
      for (int k = 0; k < std::min({3, q + 1, j + 1}); ++k)
        largest = std::max(largest, Single(rows, q - k, j - k));
    const std::vector<Expected> want = BruteForce(rows, q, 3, 5, 3);
    ASSERT_EQ(r.candidates.size(), want.size());
    for (size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(r.candidates[i].frame, want[i].frame) << "frame " << q;
      EXPECT_NEAR(r.candidates[i].distance, want[i].distance, 1e-5 * want[i].distance);
      // Float rows: divided by L x the largest single-frame distance computed so far.
      EXPECT_NEAR(r.candidates[i].normalized, want[i].distance / (3 * largest), 1e-5);
    }
  }
}

// The index blocks of each engine beyond the exact limit, against the exact detector.
class OnlineDetectorEngine : public online_test::KittiEngineTest {};

TEST_P(OnlineDetectorEngine, SearchesBlocksBeyondTheExactLimit) {
  const std::string engine = GetParam();
  const std::vector<cv::Mat> frames = ReadKitti00Frames(2, 1699);  // 850 frames
  OnlineOptions exact_options;
  exact_options.exclusion = 50;
  exact_options.candidates = 1;
  exact_options.consistency = 0;  // the score alone: what the index finds is measured
  OnlineOptions options = exact_options;
  options.approximate.engine = engine;
  options.exact_limit = 100;
  options.block_frames = 64;
  options.background_merges = false;  // repeatable block counts
  OnlineDetector exact(exact_options), approximate(options);
  OnlineOptions background_options = options;
  background_options.background_merges = true;
  OnlineDetector background(background_options);
  int same = 0, queries = 0, loops = 0, loops_found = 0;
  for (int q = 0; q < static_cast<int>(frames.size()); ++q) {
    const OnlineResult e = exact.AddFrame(frames[q]);
    const OnlineResult a = approximate.AddFrame(frames[q]);
    const OnlineResult b = background.AddFrame(frames[q]);
    for (const LoopCandidate& c : b.candidates) {  // merges in flight: still valid candidates
      EXPECT_LE(c.frame, q - 50);
      EXPECT_DOUBLE_EQ(c.distance, Single(background.Descriptors(), q, c.frame));
    }
    const int searchable = q - 50 + 1;
    EXPECT_EQ(a.approximate, searchable > 100) << "frame " << q;
    if (searchable > 100) {
      // Blocks: 64 x 2^m, one of each size at most: the binary digits of the indexed count.
      const int full = searchable / 64;
      EXPECT_EQ(approximate.Blocks(), static_cast<int>(std::bitset<32>(full).count()));
    }
    if (e.candidates.empty()) continue;
    ASSERT_EQ(a.candidates.size(), 1u);
    // Every candidate is old enough and scored with its exact distance.
    const cv::Mat rows = approximate.Descriptors();
    EXPECT_LE(a.candidates[0].frame, q - 50);
    EXPECT_DOUBLE_EQ(a.candidates[0].distance, Single(rows, q, a.candidates[0].frame));
    EXPECT_GE(a.candidates[0].distance, e.candidates[0].distance);
    ++queries;
    same += a.candidates[0].frame == e.candidates[0].frame;
    if (e.candidates[0].accepted) {
      // The frames that matter: those whose exact best match is a loop the detector accepts.
      ++loops;
      loops_found +=
          std::abs(a.candidates[0].frame - e.candidates[0].frame) <= 5 && a.candidates[0].accepted;
    }
  }
  std::printf(
      "%s: approximate top-1 = exact top-1 for %d of %d frames; accepted loops found %d of %d\n",
      engine.c_str(), same, queries, loops_found, loops);
  // LSH misses many nearest neighbours that are far anyway (non-loops: ~25 % of the bits
  // differ, so a 20-bit key rarely survives), but not the loops (~10 % differ). HNSW and IVF
  // find nearly all nearest neighbours.
  EXPECT_GT(same, (engine == "flann" ? 0.5 : 0.9) * queries);
  EXPECT_GT(loops, 20);
  EXPECT_GE(loops_found, 0.95 * loops);
  EXPECT_GT(approximate.MemoryBytes(), exact.MemoryBytes());
  background.FinishMerges();
  EXPECT_EQ(background.Blocks(), approximate.Blocks());
}

// Rows added at once (AddToMap) get their final blocks built directly: the same blocks, and so
// the same candidates, as rows added one by one through every merge, and as rows added in two
// parts (the first part's leading blocks kept).
TEST_P(OnlineDetectorEngine, RowsAddedAtOnceGetTheBlocksOfTheMerges) {
  const std::vector<cv::Mat> frames = ReadKitti00Frames(2, 999);  // 500 frames
  OnlineOptions options;
  options.approximate.engine = GetParam();
  options.exclusion = 50;
  options.candidates = 3;
  options.exact_limit = 100;
  options.block_frames = 64;
  options.background_merges = false;
  OnlineDetector one_by_one(options);
  for (int q = 0; q < 420; ++q) one_by_one.AddFrame(frames[q]);
  const cv::Mat rows = one_by_one.Descriptors().clone();
  OnlineDetector at_once(options), in_parts(options);
  at_once.AddToMap(rows);
  in_parts.AddToMap(rows.rowRange(0, 233));
  in_parts.AddToMap(rows.rowRange(233, 420));
  EXPECT_GE(one_by_one.Blocks(), 2);
  EXPECT_EQ(at_once.Blocks(), one_by_one.Blocks());
  EXPECT_EQ(in_parts.Blocks(), one_by_one.Blocks());
  for (int q = 420; q < static_cast<int>(frames.size()); ++q) {
    const OnlineResult a = one_by_one.AddFrame(frames[q]);
    const OnlineResult b = at_once.AddFrame(frames[q]);
    const OnlineResult c = in_parts.AddFrame(frames[q]);
    ASSERT_EQ(a.candidates.size(), b.candidates.size()) << q;
    ASSERT_EQ(a.candidates.size(), c.candidates.size()) << q;
    for (std::size_t i = 0; i < a.candidates.size(); ++i) {
      EXPECT_EQ(a.candidates[i].frame, b.candidates[i].frame) << q;
      EXPECT_EQ(a.candidates[i].frame, c.candidates[i].frame) << q;
      EXPECT_EQ(a.candidates[i].distance, b.candidates[i].distance) << q;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Index, OnlineDetectorEngine, online_test::IndexEngines(),
                         online_test::EngineName);

TEST(OnlineDetector, DistanceMatrixIsTheNormalisedBruteForce) {
  OPENABLE_REQUIRE_PATH(Kitti00LeftDir());
  const std::vector<cv::Mat> frames = ReadKitti00Frames(50, 1699);
  OnlineOptions options;
  const cv::Mat rows = DescribeImages(frames, options);
  float max_distance = 0;
  const cv::Mat1f m = DistanceMatrix(rows, 3, SequenceDirection::kForward, {}, 0, &max_distance, {},
                                     SequencePartial::kScale);
  double largest = 0;
  for (int i = 0; i < rows.rows; ++i)
    for (int j = 0; j < rows.rows; ++j) {
      // Both directions of the sequence sum: i's history against j's history.
      const int c = std::min({3, i + 1, j + 1});
      double s = 0;
      for (int k = 0; k < c; ++k) s += Single(rows, i - k, j - k);
      largest = std::max(largest, s * 3 / c);
    }
  EXPECT_DOUBLE_EQ(max_distance, largest);
  for (int i = 0; i < rows.rows; ++i)
    for (int j = 0; j < rows.rows; ++j) {
      const int c = std::min({3, i + 1, j + 1});
      double s = 0;
      for (int k = 0; k < c; ++k) s += Single(rows, i - k, j - k);
      EXPECT_NEAR(m(i, j), s * 3 / c / largest, 1e-6) << i << "," << j;
    }
}

TEST(OnlineDetector, BadOptionsAndFramesAreOneLineErrors) {
  auto with = [](auto change) {
    OnlineOptions o;
    change(o);
    return o;
  };
  ExpectInputError(
      [&] { OnlineDetector d(with([](OnlineOptions& o) { o.descriptor.name = "D-LDB"; })); },
      {"OnlineOptions.descriptor", "D-LDB", "stereo"});
  ExpectInputError(
      [&] { OnlineDetector d(with([](OnlineOptions& o) { o.descriptor.name = "SURF"; })); },
      {"SURF"});
  ExpectInputError([&] { OnlineDetector d(with([](OnlineOptions& o) { o.sequence_length = 0; })); },
                   {"OnlineOptions.sequence_length", "0", "1..1000"});
  ExpectInputError(
      [&] { OnlineDetector d(with([](OnlineOptions& o) { o.threshold = std::nan(""); })); },
      {"OnlineOptions.threshold", ">= 0"});
  ExpectInputError([&] { OnlineDetector d(with([](OnlineOptions& o) { o.exclusion = 0; })); },
                   {"OnlineOptions.exclusion", "0"});
  ExpectInputError(
      [&] {
        OnlineDetector d(with([](OnlineOptions& o) {
          o.candidates = 20;
          o.approximate.k = 10;
        }));
      },
      {"OnlineOptions.approximate.k", "10", "candidates"});
  OnlineOptions grid;
  grid.description = DescriptionType::kGrid;
  grid.grid_x = 8;
  OnlineDetector detector(grid);
  ExpectInputError([&] { detector.AddFrame(cv::Mat()); }, {"frame 0", "empty"});
  ExpectInputError([&] { detector.AddFrame(cv::Mat(10, 10, CV_16UC1, cv::Scalar(0))); },
                   {"frame 0", "CV_16UC1", "CV_8UC1"});
  ExpectInputError([&] { detector.AddFrame(cv::Mat(10, 4, CV_8UC1, cv::Scalar(0))); },
                   {"frame 0", "4x10", "8x1"});
  ExpectInputError([&] { detector.AddDescriptor(cv::Mat(1, 3, CV_8UC1, cv::Scalar(0))); },
                   {"descriptor row", "1x3", "expected 1x256"});
  EXPECT_EQ(detector.Size(), 0);  // nothing was added by the failures
  // A colour frame and its grey version as floats give the same row as the 8-bit grey image.
  cv::Mat grey(64, 96, CV_8UC1);
  cv::randu(grey, 0, 256);
  OnlineOptions plain;
  OnlineDetector a(plain);
  a.AddFrame(grey);
  cv::Mat bgr;
  cv::merge(std::vector<cv::Mat>{grey, grey, grey}, bgr);
  a.AddFrame(bgr);
  cv::Mat f;
  grey.convertTo(f, CV_32F, 1 / 255.0);
  a.AddFrame(f);
  EXPECT_EQ(cv::norm(a.Descriptors().row(0), a.Descriptors().row(1), cv::NORM_HAMMING), 0);
  EXPECT_EQ(cv::norm(a.Descriptors().row(0), a.Descriptors().row(2), cv::NORM_HAMMING), 0);
}

}  // namespace
}  // namespace openable
