#include "OpenABLE/snaps/loops.h"

#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

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
  ExpectInputError([&] { LoopsFromMatrix(path, WithIds({0, 1}), Options()); },
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
  for (const Case& c : {Case{"4,1\nfive,1\n", "\"five\""}, Case{"4,1\n\n3,x2\n", "\"x2\""},
                        Case{"9,1\n", "frame 9 outside"}, Case{"4\n", "1 value"},
                        Case{"-4,1\n", "frame -4"}}) {
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

}  // namespace
}  // namespace openable::snaps
