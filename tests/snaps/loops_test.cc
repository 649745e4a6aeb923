#include "OpenABLE/snaps/loops.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>

#include "OpenABLE/app/snaps_chain.h"
#include "OpenABLE/io/json.h"
#include "config/config.h"
#include "tests/test_support.h"

namespace openable::snaps {
namespace {

using openable::testing::ExpectInputError;
using openable::testing::Q;
using openable::testing::TempDir;
using openable::testing::WriteBytes;

Trajectory WithIds(std::vector<long> ids) {
  Trajectory t;
  t.format = TrajectoryFormat::kKittiWithId;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation().x() = static_cast<double>(i);
    t.poses.push_back(p);
  }
  t.frame_ids = std::move(ids);
  return t;
}

// 7 frames; M' symmetric; exclusion 2, threshold 0.3:
//  row 3: cols 0..1 -> 0.5, 0.2 -> loop (3, 1, 0.8)
//  row 4: cols 0..2 -> 0.6, 0.9, 0.4 -> none
//  row 5: cols 0..3 -> 0.1, 0.25, 0.7, 0.05 -> best 3 (0.05) -> (5, 3, 0.95)
//  row 6: cols 0..4 -> 0.2, 0.3, 0.9, 0.9, 0.2 -> best 0 (earliest of the ties) -> (6, 0, 0.8)
const char* kMatrix =
    "# normalised matrix\n"
    "0 0.7 0.7 0.5 0.6 0.1 0.2\n"
    "0.7 0 0.7 0.2 0.9 0.25 0.3\n"
    "0.7 0.7 0 0.7 0.4 0.7 0.9\n"
    "0.5 0.2 0.7 0 0.01 0.05 0.9\n"
    "0.6 0.9 0.4 0.01 0 0.01 0.2\n"
    "0.1 0.25 0.7 0.05 0.01 0 0.01\n"
    "0.2 0.3 0.9 0.9 0.2 0.01 0\n";

MatrixLoopOptions Options() {
  MatrixLoopOptions o;
  o.threshold = 0.3;
  o.exclusion = 2;
  return o;
}

TEST(LoopsFromMatrix, BestEarlierMatchBelowThreshold) {
  const std::string path = TempDir() + "/m.txt";
  WriteBytes(path, kMatrix);
  const auto loops = LoopsFromMatrix(path, WithIds({0, 1, 2, 3, 4, 5, 6}), Options());
  ASSERT_EQ(loops.size(), 3u);
  EXPECT_EQ(loops[0].query, 3);
  EXPECT_EQ(loops[0].reference, 1);
  EXPECT_NEAR(loops[0].similarity, 0.8, 1e-6);
  EXPECT_EQ(loops[1].query, 5);
  EXPECT_EQ(loops[1].reference, 3);
  EXPECT_NEAR(loops[1].similarity, 0.95, 1e-6);
  EXPECT_EQ(loops[2].query, 6);
  EXPECT_EQ(loops[2].reference, 0);
}

TEST(LoopsFromMatrix, KeyframesAndInitialOffset) {
  const std::string path = TempDir() + "/m.txt";
  WriteBytes(path, kMatrix);
  MatrixLoopOptions o = Options();
  o.initial = 10;  // row i is frame 10 + i
  // Keyframes 10, 13, 15, 16 (rows 0, 3, 5, 6): only loops with both frames keyframes.
  const Trajectory kf = WithIds({10, 13, 15, 16});
  auto loops = LoopsFromMatrix(path, kf, o);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].query, 2);  // frame 15 -> frame 13
  EXPECT_EQ(loops[0].reference, 1);
  EXPECT_EQ(loops[1].query, 3);  // frame 16 -> frame 10
  EXPECT_EQ(loops[1].reference, 0);
  // Tolerance 1: frame 11 (row 1) maps to keyframe 10 -> (3 -> 1) becomes index 1 -> 0.
  o.tolerance = 1;
  loops = LoopsFromMatrix(path, kf, o);
  ASSERT_EQ(loops.size(), 3u);
  EXPECT_EQ(loops[0].query, 1);
  EXPECT_EQ(loops[0].reference, 0);
}

TEST(LoopsFromMatrix, NotSquare) {
  const std::string path = TempDir() + "/r.txt";
  WriteBytes(path, "0 1 2\n1 0 2\n");
  ExpectInputError(
      [&] {
        LoopsFromMatrix(path, WithIds({0, 1}), Options());
      },
      {Q(path), "2x3", "not square"});
}

TEST(IndexOfFrame, ExactOrNearestWithinTolerance) {
  const Trajectory t = WithIds({0, 7, 9, 20});
  EXPECT_EQ(IndexOfFrame(t, 7, 0), 1);
  EXPECT_EQ(IndexOfFrame(t, 8, 0), -1);
  EXPECT_EQ(IndexOfFrame(t, 8, 1), 1);  // tie 7 / 9: the earlier
  EXPECT_EQ(IndexOfFrame(t, 17, 2), -1);
  EXPECT_EQ(IndexOfFrame(t, 18, 2), 3);
  EXPECT_EQ(IndexOfFrame(t, 25, 5), 3);
  EXPECT_EQ(IndexOfFrame(t, 26, 5), -1);
}

TEST(LoopsFromCsv, PairsMappedByFrameId) {
  const std::string path = TempDir() + "/pairs.csv";
  WriteBytes(path, "# row,col\n\n 13 , 10\n15,11   # 11 is no keyframe\n16,13\n");
  int dropped = -1;
  const auto loops = LoopsFromCsv(path, WithIds({10, 13, 15, 16}), 0, &dropped);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].query, 1);
  EXPECT_EQ(loops[0].reference, 0);
  EXPECT_EQ(loops[0].similarity, 1.0);
  EXPECT_EQ(loops[1].query, 3);
  EXPECT_EQ(loops[1].reference, 1);
  EXPECT_EQ(dropped, 1);
  EXPECT_EQ(LoopsFromCsv(path, WithIds({10, 13, 15, 16}), 1).size(), 3u);
}

// The file is read by the evaluation's reader (ReadPairsFile): blanks or commas, a header, the
// later frame first or second, extra columns ignored; a frame with itself is dropped.
TEST(LoopsFromCsv, SameFormatAsTheGroundTruthPairs) {
  const Trajectory t = WithIds({0, 1, 2, 3, 4, 5});
  const std::string path = TempDir() + "/pairs.txt";
  WriteBytes(path, "query reference\n4 1\n2,4\n3 3\n5,0,0.9\n");
  int dropped = -1;
  const auto loops = LoopsFromCsv(path, t, 0, &dropped);
  ASSERT_EQ(loops.size(), 3u);
  EXPECT_EQ(loops[0].query, 4);
  EXPECT_EQ(loops[0].reference, 1);
  EXPECT_EQ(loops[1].query, 4);  // "2,4": the later frame second
  EXPECT_EQ(loops[1].reference, 2);
  EXPECT_EQ(loops[2].query, 5);
  EXPECT_EQ(loops[2].reference, 0);
  EXPECT_EQ(dropped, 1);  // 3,3
}

TEST(LoopsFromCsv, Errors) {
  const Trajectory t = WithIds({0, 1, 2, 3, 4, 5});
  const std::string dir = TempDir();
  struct Case {
    std::string text, part;
  };
  for (const Case& c :
       {Case{"4,1\nfive,1\n", "\"five\""}, Case{"4,1\n\n3,x2\n", "\"x2\""},
        Case{"9,1\n", "frame 9 outside"}, Case{"4\n", "1 value"}, Case{"-4,1\n", "frame -4"}}) {
    const std::string path = dir + "/bad.csv";
    WriteBytes(path, c.text);
    const std::string line =
        c.text.rfind('\n', c.text.size() - 2) == std::string::npos
            ? ":1:"
            : ":" + std::to_string(std::count(c.text.begin(), c.text.end(), '\n')) + ":";
    ExpectInputError([&] { LoopsFromCsv(path, t); }, {Q(path) + line, c.part});
  }
  ExpectInputError([&] { LoopsFromCsv(dir + "/missing.csv", t); }, {Q(dir + "/missing.csv")});
  // A file without a pair is an error, not zero loops.
  WriteBytes(dir + "/empty.csv", "# no loops here\n\n");
  ExpectInputError([&] { LoopsFromCsv(dir + "/empty.csv", t); }, {"holds no pair"});
}

// ---------------------------------------------------------------------------------------------
// Frames that are not keyframes: a keyframe trajectory with poses at frames 0, 3, 7, 10, 14, 20
// (indices 0-5). Nearest keyframe of each frame used below, by hand (ties: the earlier pose):
//   1 -> 0 (gap 1; 3 is 2 away)           2 -> 3 (gap 1)       4 -> 3 (gap 1)
//   5 -> 3 (tie 3 / 7 at gap 2: earlier)  6 -> 7 (gap 1)       8 -> 7 (gap 1)
//   12 -> 10 (tie 10 / 14 at gap 2)       17 -> 14 (tie 14 / 20 at gap 3)   19 -> 20 (gap 1)

Trajectory Keyframes() { return WithIds({0, 3, 7, 10, 14, 20}); }

struct Expected {
  int query, reference;
};

void ExpectLoops(const std::vector<LoopPair>& loops, const std::vector<Expected>& expected) {
  ASSERT_EQ(loops.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(loops[k].query, expected[k].query) << "loop " << k;
    EXPECT_EQ(loops[k].reference, expected[k].reference) << "loop " << k;
  }
}

const char* kKeyframePairs =
    "10,0\n"   // keyframes: (3, 0)
    "20 7\n"   // keyframes: (5, 2)
    "3,14\n"   // keyframes, the later frame second: (4, 1)
    "12,1\n"   // 12 -> 10 (tie), 1 -> 0: (3, 0) with tolerance >= 2
    "19,5\n"   // 19 -> 20, 5 -> 3 (tie): (5, 1) with tolerance >= 2
    "8,2\n"    // 8 -> 7, 2 -> 3: (2, 1) with tolerance >= 1
    "17,0\n"   // 17 is 3 frames from a keyframe: dropped unless tolerance >= 3, then (4, 0)
    "4,2\n"    // both -> keyframe 3: no loop, dropped whatever the tolerance
    "7,7\n"    // a frame with itself: dropped
    "25,3\n";  // frame 25 after the last keyframe (20): outside

TEST(LoopsFromCsv, KeyframeToleranceAssociatesOrDrops) {
  const std::string path = TempDir() + "/keyframe_pairs.csv";
  WriteBytes(path, kKeyframePairs);
  const Trajectory t = Keyframes();
  struct Case {
    long tolerance;
    std::vector<Expected> loops;
    int on_poses, associated, dropped;
  };
  for (const Case& c :
       {Case{0, {{3, 0}, {5, 2}, {4, 1}}, 3, 0, 6},
        Case{1, {{3, 0}, {5, 2}, {4, 1}, {2, 1}}, 3, 1, 5},
        Case{2, {{3, 0}, {5, 2}, {4, 1}, {3, 0}, {5, 1}, {2, 1}}, 3, 3, 3},
        Case{3, {{3, 0}, {5, 2}, {4, 1}, {3, 0}, {5, 1}, {2, 1}, {4, 0}}, 3, 4, 2}}) {
    SCOPED_TRACE("tolerance " + std::to_string(c.tolerance));
    int dropped = -1, outside = -1;
    PairCounts n;
    const auto loops = LoopsFromCsv(path, t, c.tolerance, &dropped, &outside, &n);
    ExpectLoops(loops, c.loops);
    EXPECT_EQ(n.on_poses, c.on_poses);
    EXPECT_EQ(n.associated, c.associated);
    EXPECT_EQ(n.dropped, c.dropped);
    EXPECT_EQ(n.outside, 1);
    EXPECT_EQ(n.merged, 0);
    EXPECT_EQ(n.Total(), 10);
    EXPECT_EQ(dropped, c.dropped);
    EXPECT_EQ(outside, 1);
  }
  // Without `outside`, frame 25 is an error as before, whatever the counts.
  PairCounts n;
  ExpectInputError([&] { LoopsFromCsv(path, t, 2, nullptr, nullptr, &n); },
                   {Q(path) + ":10:", "frame 25 outside"});
}

// The same trajectory against a 12 x 12 matrix (row i = frame i), exclusion 5, threshold 0.3.
// Matches below the threshold (row -> best earlier column):
//   5 -> 0 (0.2): 5 -> 3 (tie) needs tolerance 2: (1, 0)
//   6 -> 0 (0.25): 6 -> 7 with tolerance >= 1: (2, 0)
//   8 -> 1 (0.05): 8 -> 7, 1 -> 0 with tolerance >= 1: (2, 0), more similar than row 6
//   10 -> 3 (0.1): keyframes: (3, 1)
//   11 -> 0 (0.2): 11 -> 10 with tolerance >= 1: (3, 0), less similar than row 10
TEST(LoopsFromMatrix, KeyframeToleranceAssociatesOrDrops) {
  cv::Mat1f m(12, 12, 0.9f);
  m(5, 0) = 0.2f;
  m(6, 0) = 0.25f;
  m(8, 1) = 0.05f;
  m(10, 3) = 0.1f;
  m(11, 0) = 0.2f;
  const Trajectory t = Keyframes();
  MatrixLoopOptions o;
  o.threshold = 0.3;
  o.exclusion = 5;
  struct Case {
    long tolerance;
    std::vector<Expected> loops;
    int on_poses, associated, dropped, merged;
  };
  for (const Case& c : {Case{0, {{3, 1}}, 1, 0, 4, 0}, Case{1, {{2, 0}, {3, 1}}, 1, 3, 1, 2},
                        Case{2, {{1, 0}, {2, 0}, {3, 1}}, 1, 4, 0, 2}}) {
    SCOPED_TRACE("tolerance " + std::to_string(c.tolerance));
    o.tolerance = c.tolerance;
    PairCounts n;
    const auto loops = LoopsFromMatrix(m, t, o, &n);
    ExpectLoops(loops, c.loops);
    EXPECT_EQ(n.on_poses, c.on_poses);
    EXPECT_EQ(n.associated, c.associated);
    EXPECT_EQ(n.dropped, c.dropped);
    EXPECT_EQ(n.outside, 0);
    EXPECT_EQ(n.merged, c.merged);
    EXPECT_EQ(n.Total(), 5);
    EXPECT_EQ(static_cast<int>(loops.size()), n.on_poses + n.associated - n.merged);
    if (c.tolerance == 1) {
      EXPECT_NEAR(loops[0].similarity, 0.95, 1e-6);  // row 8, not row 6
      EXPECT_NEAR(loops[1].similarity, 0.9, 1e-6);   // row 10, not row 11
    }
  }
}

// The chain carries the counts into its report and its JSON.
TEST(RunChain, ReportsPairsOnKeyframesAssociatedAndDropped) {
  const std::string dir = TempDir();
  const Trajectory t = Keyframes();
  WriteBytes(dir + "/keyframes.txt", EncodeTrajectory(t));
  WriteBytes(dir + "/pairs.csv", kKeyframePairs);
  Config c;
  c.snaps.trajectory = dir + "/keyframes.txt";
  c.snaps.trajectory_format = TrajectoryFormat::kKittiWithId;
  c.snaps.loops = LoopSource::kPairs;
  c.snaps.loops_file = dir + "/pairs.csv";
  c.snaps.drop_outside = true;
  c.snaps.middle_of_runs = false;
  c.snaps.corrector = Corrector::kPoseGraph;
  c.snaps.keyframe_tolerance = 2;
  std::ostringstream sink;
  ProgressReporter progress(sink, false, false);
  ChainResult r = RunChain(c, progress);
  EXPECT_EQ(r.pairs.on_poses, 3);
  EXPECT_EQ(r.pairs.associated, 3);
  EXPECT_EQ(r.pairs.dropped, 3);
  EXPECT_EQ(r.pairs.outside, 1);
  EXPECT_EQ(r.loops.size(), 6u);
  std::string report = FormatChainReport(c, r);
  EXPECT_NE(report.find("loops: 6 pairs from pairs"), std::string::npos) << report;
  EXPECT_NE(report.find("pairs file: 10 pairs: 3 on keyframes, 3 associated to the nearest "
                        "keyframe within +-2 frames, 3 dropped, 1 outside the trajectory "
                        "dropped"),
            std::string::npos)
      << report;
  const Json pairs = ChainJson(c, r).at("pairs");
  EXPECT_EQ(pairs.dump(),
            R"({"keyframe_tolerance":2,"total":10,"on_poses":3,"associated":3,"dropped":3,)"
            R"("outside":1,"merged":0})");

  // A saved matrix: the matches below the threshold; of two matches of one query keyframe, the
  // less similar is merged into the other.
  cv::Mat1f m(21, 21, 0.9f);
  m(12, 1) = 0.1f;  // 12 -> 10, 1 -> 0: (3, 0)
  m(11, 0) = 0.2f;  // 11 -> 10: (3, 0), less similar
  m(20, 3) = 0.1f;  // keyframes: (5, 1)
  m(17, 2) = 0.1f;  // 17 is 3 frames from a keyframe: dropped
  WriteBytes(dir + "/m.txt", [&] {
    std::ostringstream o;
    for (int i = 0; i < m.rows; ++i)
      for (int j = 0; j < m.cols; ++j) o << m(i, j) << (j + 1 < m.cols ? " " : "\n");
    return o.str();
  }());
  c.snaps.loops = LoopSource::kMatrix;
  c.snaps.loops_file = dir + "/m.txt";
  c.snaps.matrix_threshold = 0.3;
  c.snaps.search.frame_distance = 5;
  r = RunChain(c, progress);
  EXPECT_EQ(r.loops.size(), 2u);
  report = FormatChainReport(c, r);
  EXPECT_NE(report.find("matrix: 4 matches below 0.3: 1 on keyframes, 2 associated to the "
                        "nearest keyframe within +-2 frames, 1 dropped; 1 merged (one loop per "
                        "query keyframe, the most similar)"),
            std::string::npos)
      << report;
  // Tolerance 0: today's behaviour, only pairs on keyframes.
  c.snaps.keyframe_tolerance = 0;
  r = RunChain(c, progress);
  EXPECT_EQ(r.loops.size(), 1u);
  EXPECT_EQ(r.pairs.dropped, 3);
  report = FormatChainReport(c, r);
  EXPECT_NE(report.find("matrix: 4 matches below 0.3: 1 on keyframes, 0 associated "
                        "(Snaps_keyframe_tolerance 0), 3 dropped\n"),
            std::string::npos)
      << report;
}

}  // namespace
}  // namespace openable::snaps
