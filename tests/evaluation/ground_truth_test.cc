#include "OpenABLE/evaluation/ground_truth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/io/npy.h"
#include "tests/io/zip_writer.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using openable::testing::DatasetsDir;
using openable::testing::ExpectInputError;
using openable::testing::InputErrorMessage;
using openable::testing::Q;
using openable::testing::ReadBytes;
using openable::testing::SourceDir;
using openable::testing::TempDir;
using openable::testing::WriteBytes;
using Matches = std::vector<std::vector<int>>;
using namespace std::string_literals;

// Matches of `n` queries from a map query -> references (queries not named have none).
Matches M(int n, const std::map<int, std::vector<int>>& m) {
  Matches out(static_cast<std::size_t>(n));
  for (const auto& [q, refs] : m) out[static_cast<std::size_t>(q)] = refs;
  return out;
}

GroundTruthOptions Options(GroundTruthType type, const std::string& path) {
  GroundTruthOptions o;
  o.type = type;
  o.path = path;
  return o;
}

GroundTruth LoadLoop(const GroundTruthOptions& o, int frames) {
  return LoadGroundTruth(o, EvaluationLayout::LoopClosure(frames), frames, frames);
}

// ---------------------------------------------------------------------------------------------
// Type names and options

TEST(GroundTruthOptions, TypeNamesRoundTrip) {
  for (GroundTruthType t :
       {GroundTruthType::kNone, GroundTruthType::kMatrix, GroundTruthType::kPairs,
        GroundTruthType::kAligned, GroundTruthType::kKitti, GroundTruthType::kTum,
        GroundTruthType::kPositions}) {
    EXPECT_EQ(ParseGroundTruthType(GroundTruthTypeName(t)), t) << GroundTruthTypeName(t);
  }
  EXPECT_EQ(ParseGroundTruthType(""), GroundTruthType::kNone);
  EXPECT_EQ(ParseGroundTruthType("kitti"), GroundTruthType::kKitti);
  EXPECT_EQ(ParseGroundTruthType("TUM"), GroundTruthType::kTum);
  EXPECT_EQ(GroundTruthTypeName(GroundTruthType::kPositions), "positions");
  ExpectInputError([] { ParseGroundTruthType("gps"); }, {"Ground_truth_type", "\"gps\"", "kitti"});
}

TEST(GroundTruthOptions, CheckNamesTheKeyOfEachBadValue) {
  const std::vector<std::pair<std::function<void(GroundTruthOptions*)>, std::string>> cases = {
      {[](GroundTruthOptions* o) { o->path.clear(); }, "Ground_truth:"},
      {[](GroundTruthOptions* o) { o->radius = 0; }, "Ground_truth_radius: 0"},
      {[](GroundTruthOptions* o) { o->radius = -2; }, "Ground_truth_radius: -2"},
      {[](GroundTruthOptions* o) { o->heading_limit = 0; }, "Ground_truth_heading: 0"},
      {[](GroundTruthOptions* o) { o->heading_limit = 181; }, "Ground_truth_heading: 181"},
      {[](GroundTruthOptions* o) { o->heading_limit = -2; }, "Ground_truth_heading: -2"},
      {[](GroundTruthOptions* o) { o->min_frame_gap = -1; }, "Ground_truth_min_gap: -1"},
      {[](GroundTruthOptions* o) { o->axes = "yz"; }, "Ground_truth_axes: \"yz\""},
      {[](GroundTruthOptions* o) { o->base = 2; }, "Ground_truth_base: 2"},
      {[](GroundTruthOptions* o) { o->first_frame = -1; }, "Initial_image: -1"},
  };
  for (const auto& [mutate, key] : cases) {
    GroundTruthOptions o = Options(GroundTruthType::kKitti, "poses.txt");
    EXPECT_NO_THROW(o.Check());
    mutate(&o);
    ExpectInputError([&] { o.Check(); }, {key});
  }
  GroundTruthOptions ok = Options(GroundTruthType::kAligned, "");
  ok.heading_limit = 180;
  EXPECT_NO_THROW(ok.Check());
  EXPECT_NO_THROW(Options(GroundTruthType::kNone, "").Check());

  GroundTruthOptions positions = Options(GroundTruthType::kPositions, "xy.txt");
  EXPECT_NO_THROW(positions.Check());
  positions.heading_limit = 45;
  ExpectInputError([&] { positions.Check(); },
                   {"Ground_truth_heading: 45", "positions have no orientation"});
}

// ---------------------------------------------------------------------------------------------
// Matrix

TEST(GroundTruthMatrix, LoopClosureIsSymmetricAndDropsTheDiagonal) {
  const std::string path = TempDir() + "/gt.txt";
  // (2,0), (0,3) and its mirror (3,0), the diagonal cell (1,1).
  WriteBytes(path,
             "0 0 0 1\n"
             "0 1 0 0\n"
             "1 0 0 0\n"
             "1 0 0 0\n");
  const GroundTruth gt = LoadLoop(Options(GroundTruthType::kMatrix, path), 4);
  EXPECT_EQ(gt.matches, M(4, {{2, {0}}, {3, {0}}}));
  EXPECT_EQ(gt.references, 4);
  EXPECT_EQ(gt.dropped, 1);
  EXPECT_EQ(gt.PairCount(), 2);
  EXPECT_EQ(gt.PositiveQueries(), 2);
}

TEST(GroundTruthMatrix, BlockOrWholeMatrixOfTwoTraversals) {
  const std::string dir = TempDir();
  // 3 reference frames then 2 query frames: the block is rows 3-4, columns 0-2.
  const EvaluationLayout layout = EvaluationLayout::TwoTraversals(3, 2);
  WriteBytes(dir + "/whole.txt",
             "0 0 0 0 1\n"
             "0 0 0 0 0\n"
             "0 0 0 1 0\n"
             "0 1 0 0 0\n"
             "0 0 1 0 1\n");
  GroundTruth gt =
      LoadGroundTruth(Options(GroundTruthType::kMatrix, dir + "/whole.txt"), layout, 5, 5);
  EXPECT_EQ(gt.matches, M(2, {{0, {1}}, {1, {2}}}));
  EXPECT_EQ(gt.references, 3);
  EXPECT_EQ(gt.dropped, 0);

  WriteBytes(dir + "/block.csv", "1,0,1\n0,0,0\n");
  gt = LoadGroundTruth(Options(GroundTruthType::kMatrix, dir + "/block.csv"), layout, 5, 5);
  EXPECT_EQ(gt.matches, M(2, {{0, {0, 2}}}));

  WriteBytes(dir + "/wrong.txt", "1 0\n0 1\n");
  ExpectInputError(
      [&] { LoadGroundTruth(Options(GroundTruthType::kMatrix, dir + "/wrong.txt"), layout, 5, 5); },
      {Q(dir + "/wrong.txt"), "2x2", "expected 2x3", "5x5"});
}

TEST(GroundTruthMatrix, ImageNpyAndBadCells) {
  const std::string dir = TempDir();
  cv::Mat1b image = cv::Mat1b::zeros(4, 4);
  image(3, 1) = 255;
  image(2, 0) = 1;
  ASSERT_TRUE(cv::imwrite(dir + "/gt.png", image));
  const GroundTruth gt = LoadLoop(Options(GroundTruthType::kMatrix, dir + "/gt.png"), 4);
  EXPECT_EQ(gt.matches, M(4, {{2, {0}}, {3, {1}}}));

  // A bool .npy, written byte by byte: (1, 0) set.
  std::string header = "{'descr': '|b1', 'fortran_order': False, 'shape': (2, 2), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string npy = std::string("\x93NUMPY\x01\x00", 8);
  npy += static_cast<char>(header.size());
  npy += '\0';
  npy += header;
  npy += std::string("\x00\x00\x01\x00", 4);
  WriteBytes(dir + "/gt.npy", npy);
  EXPECT_EQ(LoadLoop(Options(GroundTruthType::kMatrix, dir + "/gt.npy"), 2).matches,
            M(2, {{1, {0}}}));

  WriteBytes(dir + "/nan.txt", "0 nan\n0 0\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kMatrix, dir + "/nan.txt"), 2); },
                   {Q(dir + "/nan.txt"), "(0, 1)", "nan"});

  // Errors of the reader say that the file is the ground truth.
  WriteBytes(dir + "/ragged.txt", "0 0 0\n0 0\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kMatrix, dir + "/ragged.txt"), 3); },
                   {"ground truth", Q(dir + "/ragged.txt") + ":2:", "row has 2 values"});
}

// ---------------------------------------------------------------------------------------------
// Pairs

TEST(GroundTruthPairs, OneBasedHeaderCommentAndDuplicates) {
  const std::string path = TempDir() + "/pairs.txt";
  WriteBytes(path, R"(# query match (1-based)
3,1
4 2
4,2
2,4   # the same as 4,2
)");
  const GroundTruth gt = LoadLoop(Options(GroundTruthType::kPairs, path), 4);
  EXPECT_EQ(gt.matches, M(4, {{2, {0}}, {3, {1}}}));
  EXPECT_EQ(gt.dropped, 0);
}

TEST(GroundTruthPairs, ZeroBasedCommentHeaderLineAndExtraColumns) {
  const std::string path = TempDir() + "/pairs.csv";
  WriteBytes(path, R"(# 0-based
row,col,distance
2,0,0.5
0,3,1.5

3,1,x
2,2
)");
  const GroundTruth gt = LoadLoop(Options(GroundTruthType::kPairs, path), 4);
  EXPECT_EQ(gt.matches, M(4, {{2, {0}}, {3, {0, 1}}}));
  EXPECT_EQ(gt.dropped, 1);  // the diagonal pair 2,2
}

// A first line is a header only when none of its fields begins like a number: one header is
// skipped and said (the report prints GroundTruth::skipped_header); a first line of numbers in
// another separator is data, refused with its value, never dropped in silence.
TEST(GroundTruthPairs, AFirstLineOfNumbersIsNeverTakenAsAHeader) {
  const std::string path = TempDir() + "/pairs_header.csv";
  WriteBytes(path, "query,match\n2,0\n3,1\n");
  GroundTruth gt = LoadLoop(Options(GroundTruthType::kPairs, path), 4);
  EXPECT_EQ(gt.matches, M(4, {{2, {0}}, {3, {1}}}));
  EXPECT_EQ(gt.skipped_header, "line 1 of " + Q(path) + ": \"query,match\"");

  WriteBytes(path, "2,0\n3,1\n");
  EXPECT_EQ(LoadLoop(Options(GroundTruthType::kPairs, path), 4).skipped_header, "");

  for (const std::string first : {"2;0", "2|0", "-1;0", ".5;1", "nan,1"}) {
    WriteBytes(path, first + "\n3,1\n");
    EXPECT_EQ(InputErrorMessage([&] {
                LoadLoop(Options(GroundTruthType::kPairs, path), 4);
              }).find("ground truth pairs " + Q(path) + ":1: "),
              0u)
        << first;
  }
  WriteBytes(path, "2;0\n3,1\n");
  EXPECT_EQ(InputErrorMessage([&] { LoadLoop(Options(GroundTruthType::kPairs, path), 4); }),
            "ground truth pairs " + Q(path) +
                ":1: line has 1 value, \"2;0\"; expected two "
                "frame indices \"a,b\" separated by a comma or blanks");
}

TEST(GroundTruthPairs, BaseOptionAndDefault) {
  const std::string path = TempDir() + "/pairs.txt";
  WriteBytes(path, "3 1\n4 2\n");
  GroundTruthOptions o = Options(GroundTruthType::kPairs, path);
  o.base = 1;
  EXPECT_EQ(LoadLoop(o, 4).matches, M(4, {{2, {0}}, {3, {1}}}));
  o.base = -1;  // no comment: 0-based
  EXPECT_EQ(LoadLoop(o, 5).matches, M(5, {{3, {1}}, {4, {2}}}));

  // 0-based, "4 2" is outside 4 frames; the message suggests Ground_truth_base.
  ExpectInputError([&] { LoadLoop(o, 4); },
                   {Q(path) + ":2:", "pair 4,2", "out of range", "[0, 3]", "Ground_truth_base"});

  WriteBytes(path, "# 0-based indices, converted from the 1-based originals\n1 0\n");
  ExpectInputError([&] { LoadLoop(o, 4); }, {Q(path), "0-based", "1-based", "Ground_truth_base"});
}

TEST(GroundTruthPairs, OutOfRangeMessagesNameTheLinePairAndRange) {
  const std::string dir = TempDir();
  WriteBytes(dir + "/one.txt", "# 1-based\n2 1\n1 0\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kPairs, dir + "/one.txt"), 4); },
                   {Q(dir + "/one.txt") + ":3:", "pair 1,0", "[1, 4]", "1-based"});

  const EvaluationLayout layout = EvaluationLayout::QueryReference(2, 3);
  WriteBytes(dir + "/qr.txt", "1,2\n0,0\n2,0\n");
  ExpectInputError(
      [&] { LoadGroundTruth(Options(GroundTruthType::kPairs, dir + "/qr.txt"), layout, 2, 3); },
      {Q(dir + "/qr.txt") + ":3:", "pair 2,0", "query indices in [0, 1]",
       "reference indices in [0, 2]"});

  WriteBytes(dir + "/short.txt", "3\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kPairs, dir + "/short.txt"), 4); },
                   {Q(dir + "/short.txt") + ":1:", "1 value", "two frame indices"});
  WriteBytes(dir + "/word.txt", "3,1\n3,b\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kPairs, dir + "/word.txt"), 4); },
                   {Q(dir + "/word.txt") + ":2:", "\"b\"", "not an integer"});
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kPairs, dir + "/absent.txt"), 4); },
                   {Q(dir + "/absent.txt"), "does not exist"});
  // An empty ground truth would give figures of 0 for any matrix: refused.
  WriteBytes(dir + "/empty.txt", "query,reference\n# nothing\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kPairs, dir + "/empty.txt"), 4); },
                   {Q(dir + "/empty.txt"), "holds no pair"});
}

// Found with tests/fuzz/ground_truth_fuzzer.cc (reading the code; the fuzzer's binary
// confirmed it under UBSan): an index of -2^63 in a 1-based file, or of -2^63 + 1 read from
// frame 3, overflowed when the base or the first frame was subtracted (undefined behaviour).
// Indices are now integers of at most 10^15 in size. The inputs are the fuzzer's, whose first
// byte chooses the reader and its options (pairs 1-based; pairs 0-based from frame 3).
TEST(GroundTruthPairs, IndicesBeyondTenToTheFifteenAreRefused) {
  struct Case {
    const char* name;
    int base, first_frame;
  };
  for (const Case& c :
       {Case{"pairs_int64_min_1based.txt", 1, 0}, Case{"pairs_int64_from_frame_3.txt", 0, 3}}) {
    const std::string path = TempDir() + "/" + c.name;
    const std::string input = ReadBytes(SourceDir() + "/tests/fuzz/corpus/ground_truth/" + c.name);
    WriteBytes(path, input.substr(1));
    GroundTruthOptions o = Options(GroundTruthType::kPairs, path);
    o.base = c.base;
    o.first_frame = c.first_frame;
    ExpectInputError([&] { LoadLoop(o, 40); },
                     {Q(path) + ":1:", "column 1", "not an integer of at most 10^15 in size"});
  }
  // 10^15 itself is an index: here out of the range of the run.
  const std::string path = TempDir() + "/bound.txt";
  WriteBytes(path, "-1000000000000000,1\n");
  ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kPairs, path), 40); },
                   {Q(path) + ":1:", "pair -1000000000000000,1", "out of range"});
}

TEST(GroundTruthPairs, QueryReferenceKeepsTheOrder) {
  const std::string path = TempDir() + "/pairs.txt";
  WriteBytes(path, "1,2\n0,0\n1,0\n");
  const GroundTruth gt = LoadGroundTruth(Options(GroundTruthType::kPairs, path),
                                         EvaluationLayout::QueryReference(2, 3), 2, 3);
  EXPECT_EQ(gt.matches, M(2, {{0, {0}}, {1, {0, 2}}}));
  EXPECT_EQ(gt.references, 3);
}

TEST(GroundTruthPairs, FirstFrameShiftsAndDropsPairsOutsideTheRange) {
  const std::string path = TempDir() + "/pairs.txt";
  // Frames 10..14 of the source are rows 0..4.
  WriteBytes(path,
             "12,10\n"
             "11,14\n"
             "15,12\n"    // 15 is after the range: dropped
             "12,3\n"     // 3 is before it: dropped
             "11,11\n");  // diagonal: dropped
  GroundTruthOptions o = Options(GroundTruthType::kPairs, path);
  o.first_frame = 10;
  const GroundTruth gt = LoadLoop(o, 5);
  EXPECT_EQ(gt.matches, M(5, {{2, {0}}, {4, {1}}}));
  EXPECT_EQ(gt.dropped, 3);

  // A negative index is wrong whatever the range.
  WriteBytes(path, "12,10\n-1,12\n");
  ExpectInputError([&] { LoadLoop(o, 5); }, {Q(path) + ":2:", "pair -1,12", ">= 0"});

  // A range that starts at frame 0 but ends early (Final_image set): pairs past its end are
  // dropped too; without a range they are an error.
  WriteBytes(path, "3,1\n7,2\n");
  o.first_frame = 0;
  o.range_selected = true;
  const GroundTruth ranged = LoadLoop(o, 5);
  EXPECT_EQ(ranged.matches, M(5, {{3, {1}}}));
  EXPECT_EQ(ranged.dropped, 1);
  o.range_selected = false;
  EXPECT_THROW(LoadLoop(o, 5), InputError);
}

// ---------------------------------------------------------------------------------------------
// Aligned

TEST(GroundTruthAligned, QueryIIsReferenceI) {
  GroundTruthOptions o = Options(GroundTruthType::kAligned, "");
  const GroundTruth gt = LoadGroundTruth(o, EvaluationLayout::TwoTraversals(3, 3), 6, 6);
  EXPECT_EQ(gt.matches, M(3, {{0, {0}}, {1, {1}}, {2, {2}}}));
  EXPECT_EQ(gt.references, 3);
  // Traversals of unequal length: frame i has no counterpart to be paired with.
  try {
    LoadGroundTruth(o, EvaluationLayout::TwoTraversals(2, 3), 5, 5);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "Ground_truth_type: aligned pairs query frame i with reference frame i, but the "
                 "query traversal has 3 frames and the reference traversal 2; expected "
                 "traversals of equal length (else a pairs or poses ground truth)");
  }
  try {
    LoadLoop(o, 4);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "Ground_truth_type: aligned needs two traversals (Images_path_2 or Frame_mode "
                 "2)");
  }
}

// ---------------------------------------------------------------------------------------------
// Poses

// A square loop in KITTI's ground plane (x, z; y points down), the camera looking along its
// third column: frames 0-3 go round a 10 m square, 4 comes back 1 m beside the start facing
// -x, 5 is 1 m from the start facing +z but 3 m higher, 6 and 7 repeat frames 1 and 2.
//   frame:     0        1        2         3         4        5        6        7
//   (x, z):  (0,0)   (0,10)  (10,10)   (10,0)    (1,0)    (0,1)   (0,10)  (10,10)
//   facing:   +z       +z       +x        -z        -x       +z       +z       +x
const char* const kSquareKitti[] = {
    "1 0 0 0 0 1 0 0 0 0 1 0",     // 0
    "1 0 0 0 0 1 0 0 0 0 1 10",    // 1
    "0 0 1 10 0 1 0 0 -1 0 0 10",  // 2
    "-1 0 0 10 0 1 0 0 0 0 -1 0",  // 3
    "0 0 -1 1 0 1 0 0 1 0 0 0",    // 4
    "1 0 0 0 0 1 0 -3 0 0 1 1",    // 5
    "1 0 0 0 0 1 0 0 0 0 1 10",    // 6
    "0 0 1 10 0 1 0 0 -1 0 0 10",  // 7
};

std::string KittiLines(int begin, int end) {
  std::string s;
  for (int i = begin; i < end; ++i) s += std::string(kSquareKitti[i]) + "\n";
  return s;
}

TEST(PosesKitti, ReadsPositionsAndForwardVectors) {
  const std::string path = TempDir() + "/poses.txt";
  WriteBytes(path, KittiLines(0, 8));
  const std::vector<FramePose> poses = ReadPoses(path, GroundTruthType::kKitti);
  ASSERT_EQ(poses.size(), 8u);
  EXPECT_EQ(poses[2].position, Eigen::Vector3d(10, 0, 10));
  EXPECT_EQ(poses[2].forward, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(poses[3].forward, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(poses[4].forward, Eigen::Vector3d(-1, 0, 0));
  EXPECT_EQ(poses[5].position, Eigen::Vector3d(0, -3, 1));
  EXPECT_TRUE(poses[0].has_forward);
}

// The square loop's 8 poses in a fresh file, compared within 2 m over x and z, 3 frames apart.
GroundTruthOptions SquareLoop() {
  const std::string path = TempDir() + "/poses.txt";
  WriteBytes(path, KittiLines(0, 8));
  GroundTruthOptions o = Options(GroundTruthType::kKitti, path);
  o.radius = 2;
  o.axes = "xz";
  o.min_frame_gap = 3;
  return o;
}

TEST(PosesKitti, SquareLoopWithRadiusHeadingGapAndAxes) {
  GroundTruthOptions o = SquareLoop();
  // 4-0 and 5-0 are 1 m apart, 6-1 and 7-2 at the same place.
  GroundTruth gt = LoadLoop(o, 8);
  EXPECT_EQ(gt.matches, M(8, {{4, {0}}, {5, {0}}, {6, {1}}, {7, {2}}}));
  EXPECT_EQ(gt.dropped, 0);

  // 4 faces -x where 0 faces +z: 90 degrees.
  o.heading_limit = 45;
  EXPECT_EQ(LoadLoop(o, 8).matches, M(8, {{5, {0}}, {6, {1}}, {7, {2}}}));
  o.heading_limit = -1;

  // 4-0 is only 4 frames apart.
  o.min_frame_gap = 5;
  EXPECT_EQ(LoadLoop(o, 8).matches, M(8, {{5, {0}}, {6, {1}}, {7, {2}}}));

  // Gap 0: 5-4 (1.41 m) joins, the diagonal pairs are dropped and counted.
  o.min_frame_gap = 0;
  gt = LoadLoop(o, 8);
  EXPECT_EQ(gt.matches, M(8, {{4, {0}}, {5, {0, 4}}, {6, {1}}, {7, {2}}}));
  EXPECT_EQ(gt.dropped, 8);
  o.min_frame_gap = 3;

  // The distance must be below the radius: 1 m is not below 1 m.
  o.radius = 1;
  EXPECT_EQ(LoadLoop(o, 8).matches, M(8, {{6, {1}}, {7, {2}}}));
  o.radius = 2;

  // In 3D, 5 is sqrt(1 + 9) m from 0.
  o.axes = "xyz";
  EXPECT_EQ(LoadLoop(o, 8).matches, M(8, {{4, {0}}, {6, {1}}, {7, {2}}}));

  // Over x and y, frames 0, 1, 6 (x = 0) and 2, 3, 7 (x = 10) coincide, 4 is 1 m from x = 0.
  o.axes = "xy";
  EXPECT_EQ(LoadLoop(o, 8).matches, M(8, {{4, {0, 1}}, {6, {0, 1}}, {7, {2, 3}}}));
}

TEST(PosesKitti, FirstFrameSelectsPoseLines) {
  GroundTruthOptions o = SquareLoop();
  o.first_frame = 2;
  // Rows 0..5 are frames 2..7: only 7-2 remains.
  EXPECT_EQ(LoadLoop(o, 6).matches, M(6, {{5, {0}}}));
  ExpectInputError([&] { LoadLoop(o, 7); },
                   {"KITTI poses " + Q(o.path), "file has 8 poses", "needs 9", "Initial_image 2"});
}

TEST(PosesKitti, TwoTraversals) {
  const std::string dir = TempDir();
  WriteBytes(dir + "/reference.txt", KittiLines(0, 4));
  WriteBytes(dir + "/query.txt", KittiLines(4, 8));
  GroundTruthOptions o = Options(GroundTruthType::kKitti, dir + "/reference.txt");
  o.path_2 = dir + "/query.txt";
  o.radius = 2;
  o.axes = "xz";
  const EvaluationLayout layout = EvaluationLayout::TwoTraversals(4, 4);
  GroundTruth gt = LoadGroundTruth(o, layout, 8, 8);
  EXPECT_EQ(gt.matches, M(4, {{0, {0}}, {1, {0}}, {2, {1}}, {3, {2}}}));
  EXPECT_EQ(gt.references, 4);
  o.heading_limit = 45;
  EXPECT_EQ(LoadGroundTruth(o, layout, 8, 8).matches, M(4, {{1, {0}}, {2, {1}}, {3, {2}}}));

  o.path_2.clear();
  ExpectInputError([&] { LoadGroundTruth(o, layout, 8, 8); }, {"Ground_truth_2"});
  o.path_2 = dir + "/query.txt";
  ExpectInputError([&] { LoadGroundTruth(o, EvaluationLayout::TwoTraversals(4, 5), 9, 9); },
                   {"KITTI poses " + Q(dir + "/query.txt"), "file has 4 poses", "needs 5"});
}

TEST(PosesTum, QuaternionHeadingExcludesOppositeViews) {
  const std::string path = TempDir() + "/trajectory.txt";
  // Same spot: facing +z; facing -z (180 degrees about y); 0.5 m away turned by 30 degrees
  // about y. (A quaternion that is not of unit norm is refused, as SNAPS refuses it.)
  WriteBytes(path,
             "# timestamp tx ty tz qx qy qz qw\n"
             "1305031102.175304 1 2 3 0 0 0 1\n"
             "1305031102.211214 1 2 3 0 1 0 0\n"
             "1305031102.243211 1.5 2 3 0 0.25881904510252074 0 0.9659258262890683\n");
  const std::vector<FramePose> poses = ReadPoses(path, GroundTruthType::kTum);
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[2].position, Eigen::Vector3d(1.5, 2, 3));
  EXPECT_TRUE(poses[1].forward.isApprox(Eigen::Vector3d(0, 0, -1), 1e-12)) << poses[1].forward;
  EXPECT_TRUE(poses[2].forward.isApprox(Eigen::Vector3d(0.5, 0, std::sqrt(3.0) / 2), 1e-12))
      << poses[2].forward;

  GroundTruthOptions o = Options(GroundTruthType::kTum, path);
  o.radius = 1;
  o.min_frame_gap = 1;
  EXPECT_EQ(LoadLoop(o, 3).matches, M(3, {{1, {0}}, {2, {0, 1}}}));
  o.heading_limit = 45;  // 180, 30 and 150 degrees
  EXPECT_EQ(LoadLoop(o, 3).matches, M(3, {{2, {0}}}));
}

TEST(PosesPositions, HeaderTwoColumnsAndNoHeading) {
  const std::string path = TempDir() + "/positions.csv";
  WriteBytes(path, "x,y\n0,0\n0.5,0\n3,0\n0.6,0.1\n");
  const std::vector<FramePose> poses = ReadPoses(path, GroundTruthType::kPositions);
  ASSERT_EQ(poses.size(), 4u);
  EXPECT_EQ(poses[3].position, Eigen::Vector3d(0.6, 0.1, 0));
  EXPECT_FALSE(poses[3].has_forward);

  GroundTruthOptions o = Options(GroundTruthType::kPositions, path);
  o.radius = 1;
  o.min_frame_gap = 2;
  EXPECT_EQ(LoadLoop(o, 4).matches, M(4, {{3, {0, 1}}}));

  o.heading_limit = 45;
  ExpectInputError([&] { LoadLoop(o, 4); },
                   {"Ground_truth_heading", "positions have no orientation"});
  ExpectInputError([&] { PairsFromPoses(poses, {}, o); }, {"Ground_truth_heading"});

  WriteBytes(path, "0 0\n1 2 3\n");
  ExpectInputError(
      [&] { ReadPoses(path, GroundTruthType::kPositions); },
      {"positions " + Q(path) + ":2:", "3 numbers", "expected 2", "first position (line 1)"});
}

TEST(PosesHeading, ProjectionAndStrictLimit) {
  auto pose = [](Eigen::Vector3d forward) {
    FramePose p;
    p.forward = forward;
    p.has_forward = true;
    return p;
  };
  // Both at the origin; the query looks down (y), the reference along z.
  const std::vector<FramePose> down = {pose({0, 1, 0})};
  const std::vector<FramePose> ahead = {pose({0, 0, 1})};
  GroundTruthOptions o;
  o.radius = 1;
  o.axes = "xz";
  EXPECT_EQ(PairsFromPoses(down, ahead, o), M(1, {{0, {0}}}));
  o.heading_limit = 180;  // a direction with no projection on xz has no heading
  EXPECT_EQ(PairsFromPoses(down, ahead, o), M(1, {}));
  o.axes = "xyz";  // 90 degrees in 3D
  EXPECT_EQ(PairsFromPoses(down, ahead, o), M(1, {{0, {0}}}));
  o.heading_limit = 90;  // not below 90
  EXPECT_EQ(PairsFromPoses(down, ahead, o), M(1, {}));
  o.heading_limit = 90.001;
  EXPECT_EQ(PairsFromPoses(down, ahead, o), M(1, {{0, {0}}}));

  // Opposite directions are 180 degrees apart, not below a limit of 180.
  o.heading_limit = 180;
  EXPECT_EQ(PairsFromPoses({pose({0, 0, -1})}, ahead, o), M(1, {}));
}

TEST(PosesErrors, MalformedFilesNameFileAndLine) {
  const std::string dir = TempDir();
  WriteBytes(dir + "/k.txt", std::string(kSquareKitti[0]) + "\n1 0 0 0 0 1 0 0 0 0 1\n");
  ExpectInputError([&] { ReadPoses(dir + "/k.txt", GroundTruthType::kKitti); },
                   {"KITTI poses " + Q(dir + "/k.txt") + ":2:", "11 numbers", "expected 12"});
  WriteBytes(dir + "/x.txt", "1 0 0 0 0 1 0 0 0 0 1 x\n");
  ExpectInputError([&] { ReadPoses(dir + "/x.txt", GroundTruthType::kKitti); },
                   {Q(dir + "/x.txt") + ":1:", "\"x\"", "column 12"});
  WriteBytes(dir + "/t.txt", "# tum\n0 1 2 3 0 0 0\n");
  ExpectInputError([&] { ReadPoses(dir + "/t.txt", GroundTruthType::kTum); },
                   {"TUM trajectory " + Q(dir + "/t.txt") + ":2:", "7 numbers", "expected 8"});
  WriteBytes(dir + "/q.txt", "0 1 2 3 0 0 0 0\n");
  ExpectInputError([&] { ReadPoses(dir + "/q.txt", GroundTruthType::kTum); },
                   {Q(dir + "/q.txt") + ":1:", "quaternion"});
  WriteBytes(dir + "/empty.txt", "# nothing\n");
  ExpectInputError([&] { ReadPoses(dir + "/empty.txt", GroundTruthType::kKitti); },
                   {Q(dir + "/empty.txt"), "no pose"});
  ExpectInputError([&] { ReadPoses(dir + "/absent.txt", GroundTruthType::kTum); },
                   {Q(dir + "/absent.txt"), "does not exist"});
  EXPECT_THROW(ReadPoses(dir + "/k.txt", GroundTruthType::kMatrix), std::logic_error);
  // A frame number before the 12 numbers: the evaluation has no format for keyframes (one pose
  // per frame), so the message names none.
  WriteBytes(dir + "/ids.txt", "0 1 0 0 0 0 1 0 0 0 0 1 0\n");
  const std::string ids =
      InputErrorMessage([&] { ReadPoses(dir + "/ids.txt", GroundTruthType::kKitti); });
  EXPECT_NE(ids.find("13 numbers; expected 12"), std::string::npos) << ids;
  EXPECT_EQ(ids.find("kitti-id"), std::string::npos) << ids;
  // The checks SNAPS applies to the same files (one reader, pose_file.h): a matrix that is not
  // a rotation, timestamps out of order.
  WriteBytes(dir + "/scaled.txt", "2 0 0 0 0 2 0 0 0 0 2 0\n");
  ExpectInputError([&] { ReadPoses(dir + "/scaled.txt", GroundTruthType::kKitti); },
                   {Q(dir + "/scaled.txt") + ":1:", "not a rotation"});
  WriteBytes(dir + "/late.txt", "0.5 1 2 3 0 0 0 1\n0.25 1 2 3 0 0 0 1\n");
  ExpectInputError([&] { ReadPoses(dir + "/late.txt", GroundTruthType::kTum); },
                   {Q(dir + "/late.txt") + ":2:", "timestamp 0.25 after 0.5"});
}

// ---------------------------------------------------------------------------------------------
// Real data

std::set<std::pair<int, int>> PairSet(const Matches& m) {
  std::set<std::pair<int, int>> s;
  for (std::size_t q = 0; q < m.size(); ++q) {
    for (int r : m[q]) s.insert({static_cast<int>(q), r});
  }
  return s;
}

TEST(GroundTruthKitti00, PosesReproduceLoopGt5m) {
  const std::string dir = DatasetsDir() + "/kitti00_first1700";
  OPENABLE_REQUIRE_PATH(dir + "/loop_gt_5m.txt");
  // "query candidate dist_m heading_deg" per line.
  std::set<std::pair<int, int>> all, below_45;
  std::ifstream f(dir + "/loop_gt_5m.txt");
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream is(line);
    int q = 0, c = 0;
    double dist = 0, heading = 0;
    ASSERT_TRUE(is >> q >> c >> dist >> heading) << line;
    all.insert({q, c});
    if (heading < 45) below_45.insert({q, c});
  }
  ASSERT_EQ(all.size(), 1263u);

  GroundTruthOptions o = Options(GroundTruthType::kKitti, dir + "/poses/00_first1700.txt");
  o.radius = 5;
  o.axes = "xz";
  o.min_frame_gap = 100;
  GroundTruth gt = LoadLoop(o, 1700);
  EXPECT_EQ(PairSet(gt.matches), all);
  EXPECT_EQ(gt.PairCount(), 1263);
  EXPECT_EQ(gt.dropped, 0);

  o.heading_limit = 45;
  gt = LoadLoop(o, 1700);
  EXPECT_EQ(PairSet(gt.matches), below_45);
  EXPECT_LT(below_45.size(), all.size());
}

TEST(GroundTruthRtabmap, OneBasedPairsEqualTheMatrixAndTheBmp) {
  const std::string dir = DatasetsDir() + "/rtabmap_samples";
  OPENABLE_REQUIRE_PATH(dir + "/ground_truth_pairs.txt");
  const GroundTruth pairs =
      LoadLoop(Options(GroundTruthType::kPairs, dir + "/ground_truth_pairs.txt"), 84);
  const GroundTruth matrix =
      LoadLoop(Options(GroundTruthType::kMatrix, dir + "/ground_truth_matrix.txt"), 84);
  const GroundTruth bmp = LoadLoop(Options(GroundTruthType::kMatrix, dir + "/samples_GT.bmp"), 84);
  EXPECT_EQ(pairs.PairCount(), 228);
  EXPECT_EQ(pairs.matches, matrix.matches);
  EXPECT_EQ(pairs.matches, bmp.matches);
  // Images 41..84 revisit 1..44: 1-based 41,1 is row 40, column 0.
  EXPECT_EQ(pairs.matches[40], std::vector<int>({0, 1, 2}));
  EXPECT_EQ(pairs.dropped, 0);
  EXPECT_EQ(matrix.dropped, 0);
}

// ---------------------------------------------------------------------------------------------
// VPR-Bench's and VPR_Tutorial's files (tests/data/reference_protocols/make.py and
// tests/data/npy_objects/make.py wrote them; their contents are stated here)

std::string ProtocolData(const std::string& file) {
  return SourceDir() + "/tests/data/reference_protocols/" + file;
}

GroundTruth LoadQueryReference(const GroundTruthOptions& o, int queries, int references) {
  return LoadGroundTruth(o, EvaluationLayout::QueryReference(queries, references), queries,
                         references);
}

TEST(GroundTruthVprBench, ListsPerQueryAndReferencesPastTheLastDropped) {
  const GroundTruthOptions o =
      Options(GroundTruthType::kVprBench, ProtocolData("hand_ground_truth.npy"));
  // make.py's lists: [0, 1], [2], [3, 4, 5], [8], [], [1], [6, 7].
  const std::vector<std::vector<int>> lists = {{0, 1}, {2}, {3, 4, 5}, {8}, {}, {1}, {6, 7}};
  GroundTruth gt = LoadQueryReference(o, 7, 9);
  EXPECT_EQ(gt.matches, lists);
  EXPECT_EQ(gt.dropped, 0);
  EXPECT_TRUE(gt.soft.empty());
  // With 5 references, 5, 8, 6 and 7 are past the last: dropped, not refused.
  gt = LoadQueryReference(o, 7, 5);
  EXPECT_EQ(gt.matches, (std::vector<std::vector<int>>{{0, 1}, {2}, {3, 4}, {}, {}, {1}, {}}));
  EXPECT_EQ(gt.dropped, 4);
  // From frame 1 on (Initial_image 1): row i is query i - 1, reference r is column r - 1.
  GroundTruthOptions ranged = o;
  ranged.first_frame = 1;
  gt = LoadQueryReference(ranged, 6, 8);
  EXPECT_EQ(gt.matches, (std::vector<std::vector<int>>{{1}, {2, 3, 4}, {7}, {}, {0}, {5, 6}}));
  EXPECT_EQ(gt.dropped, 2);  // query 0's references 0 and 1
}

TEST(GroundTruthVprBench, BadFilesAndLayoutsAreOneLineNamingTheFile) {
  const std::string hand = ProtocolData("hand_ground_truth.npy");
  testing::ExpectInputError(
      [&] { LoadQueryReference(Options(GroundTruthType::kVprBench, hand), 6, 9); },
      {"VPR-Bench ground truth \"" + hand + "\": 7 queries; expected 6"});
  testing::ExpectInputError([&] { LoadLoop(Options(GroundTruthType::kVprBench, hand), 9); },
                            {"Ground_truth_type: vpr_bench needs two traversals"});
  // gt_lists.npy's last row names reference -5.
  const std::string lists = SourceDir() + "/tests/data/npy_objects/gt_lists.npy";
  testing::ExpectInputError(
      [&] { LoadQueryReference(Options(GroundTruthType::kVprBench, lists), 4, 9); },
      {"gt_lists.npy\": row 3 names reference -5; expected indices >= 0"});
  // A numeric matrix is not a list per query; a pickle that calls a function is refused.
  const std::string numeric = ProtocolData("hand_distances.npy");
  testing::ExpectInputError(
      [&] { LoadQueryReference(Options(GroundTruthType::kVprBench, numeric), 7, 9); },
      {"an array of shape (7, 9); expected (queries, 2)"});
  const std::string evil = SourceDir() + "/tests/data/npy_objects/evil.npy";
  testing::ExpectInputError(
      [&] { LoadQueryReference(Options(GroundTruthType::kVprBench, evil), 1, 9); },
      {"evil.npy", "posix.system"});
}

TEST(GroundTruthMissingFiles, EveryFormatNamesTheFileItLookedFor) {
  const std::string dir = TempDir();
  for (const GroundTruthFormat& f : GroundTruthFormats()) {
    if (!f.needs_file) continue;
    const std::string absent = dir + "/absent_" + f.name + ".npy";
    const std::string message = InputErrorMessage([&] {
      LoadGroundTruth(Options(GroundTruthType(f.name), absent),
                      EvaluationLayout::TwoTraversals(3, 3), 6, 6);
    });
    // Pose formats of two traversals want the query poses too; give them.
    if (message.find("Ground_truth_2") != std::string::npos) {
      GroundTruthOptions o = Options(GroundTruthType(f.name), absent);
      o.path_2 = absent;
      ExpectInputError([&] { LoadGroundTruth(o, EvaluationLayout::TwoTraversals(3, 3), 6, 6); },
                       {Q(absent), "does not exist"});
      continue;
    }
    EXPECT_NE(message.find(std::string(f.label) + " " + Q(absent) + " does not exist"),
              std::string::npos)
        << f.name << ": " << message;
  }
  // VPR_Tutorial's separate GTsoft too.
  GroundTruthOptions o = Options(GroundTruthType::kVprTutorial, ProtocolData("hand_gt_hard.npy"));
  o.soft_path = dir + "/absent_soft.npy";
  ExpectInputError([&] { LoadQueryReference(o, 7, 9); },
                   {"VPR_Tutorial soft ground truth " + Q(o.soft_path) + " does not exist"});
}

TEST(GroundTruthVprTutorial, MatricesAreDatabaseByQueries) {
  GroundTruthOptions o = Options(GroundTruthType::kVprTutorial, ProtocolData("hand_gt_hard.npy"));
  const GroundTruth gt = LoadQueryReference(o, 7, 9);
  EXPECT_EQ(gt.matches,
            (std::vector<std::vector<int>>{{0, 1}, {2}, {3, 4, 5}, {8}, {}, {1}, {6, 7}}));
  // The matrix transposed (queries x references) is not VPR_Tutorial's orientation.
  testing::ExpectInputError([&] { LoadQueryReference(o, 9, 7); },
                            {"hand_gt_hard.npy\": 9x7 (database x queries); expected 7x9"});
  o.soft_path = ProtocolData("hand_distances.npy");  // 7 x 9: the wrong orientation too
  testing::ExpectInputError([&] { LoadQueryReference(o, 7, 9); },
                            {"soft ground truth", "hand_distances.npy"});
  GroundTruthOptions pairs = Options(GroundTruthType::kPairs, "gt.txt");
  pairs.soft_path = ProtocolData("hand_gt_soft.npy");
  testing::ExpectInputError([&] { pairs.Check(); },
                            {"Ground_truth_soft: ", "expected Ground_truth_type vpr_tutorial"});
  // A zip64 archive holding GThard = eye(3) and no GTsoft.
  const GroundTruth eye = LoadQueryReference(
      Options(GroundTruthType::kVprTutorial, SourceDir() + "/tests/data/npy_objects/zip64.npz"), 3,
      3);
  EXPECT_EQ(eye.matches, (std::vector<std::vector<int>>{{0}, {1}, {2}}));
  EXPECT_TRUE(eye.soft.empty());
}

// A bool .npy of rows x cols whose cell (i, i) is `diagonal`, the others false.
std::string DiagonalNpy(int rows, int cols, bool diagonal = true) {
  std::string data =
      NpyHeaderOf("'|b1'", "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")");
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) data += static_cast<char>(i == j && diagonal ? 1 : 0);
  return data;
}

// GT.npz archives: a member larger than the run's references x queries can be is refused by
// the size the archive declares, before it is inflated (np.savez_compressed of 16384 x 16384
// zeros is 261 kB and inflates to 256 MiB); two members of one name (np.load reads the last)
// and an archive without members are refused in one line naming the file.
TEST(GroundTruthVprTutorial, ArchivesLargerThanTheRunOrReadOtherwiseByNumpyAreRefused) {
  using testing::ZipArchive;
  const std::string dir = TempDir(), path = dir + "/GT.npz";
  const GroundTruthOptions o = Options(GroundTruthType::kVprTutorial, path);
  // Sound: GThard = eye(10), GTsoft with nothing more.
  WriteBytes(path, ZipArchive({{"GThard.npy", DiagonalNpy(10, 10)},
                               {"GTsoft.npy", DiagonalNpy(10, 10, false)}}));
  const GroundTruth eye = LoadQueryReference(o, 10, 10);
  ASSERT_EQ(eye.matches.size(), 10u);
  for (int q = 0; q < 10; ++q) EXPECT_EQ(eye.matches[q], std::vector<int>{q});
  // 300 x 300: 90000 cells and the header, where 10 x 10 takes 65536 + 8 x 100 bytes at most.
  const std::size_t large = DiagonalNpy(300, 300).size();
  WriteBytes(path, ZipArchive({{"GThard.npy", DiagonalNpy(300, 300)}}));
  ExpectInputError([&] { LoadQueryReference(o, 10, 10); },
                   {"VPR_Tutorial ground truth " + Q(path) + ": member \"GThard.npy\" holds " +
                    std::to_string(large) +
                    " bytes once inflated (the size the archive declares); expected at most " +
                    std::to_string(65536 + 8 * 100) + ": a 10x10 matrix (database x queries)"});
  // GThard of the run's size, but a GTsoft of 300 x 300.
  WriteBytes(path, ZipArchive({{"GThard.npy", DiagonalNpy(10, 10)},
                               {"GTsoft.npy", DiagonalNpy(300, 300)}}));
  ExpectInputError([&] { LoadQueryReference(o, 10, 10); },
                   {"member \"GTsoft.npy\" holds " + std::to_string(large) + " bytes"});
  // Two GThard: np.load (so VPR_Tutorial) reads the second, which holds no pair.
  WriteBytes(path, ZipArchive({{"GThard.npy", DiagonalNpy(10, 10)},
                               {"GThard.npy", DiagonalNpy(10, 10, false)}}));
  ExpectInputError([&] { LoadQueryReference(o, 10, 10); },
                   {"VPR_Tutorial ground truth " + Q(path) +
                    ": the archive holds two members named \"GThard.npy\""});
  // No member at all.
  WriteBytes(path, ZipArchive({}));
  ExpectInputError([&] { LoadQueryReference(o, 10, 10); },
                   {"VPR_Tutorial ground truth " + Q(path) +
                    ": is an empty ZIP archive (no member); expected one holding \"GThard.npy\""});
}

// VPR-Bench files whose lists hold more numbers than the run can use are refused before the
// numbers are made: a range memoised once and named by every row (a 475-byte file of 49 rows
// naming range(2000000) took 331 MB and 3 s, and was evaluated).
TEST(GroundTruthVprBench, ListsLongerThanTheRunCanUseAreRefusedBeforeTheyAreMade) {
  const std::string dir = TempDir(), path = dir + "/gt.npy";
  // A (3, 2) object array as Python 2 pickles it (protocol 2), row q = [q, range(0, n)]: the
  // range made for row 0, memoised, and named again by rows 1 and 2.
  const auto rows_naming_one_range = [](std::uint16_t n) {
    std::string p =
        "\x80\x02"
        "cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\nK\x00\x85U\x01"
        "b\x87R(K\x01K\x03K\x02\x86"
        "cnumpy\ndtype\nU\x02O8K\x00K\x01\x87R(K\x03U\x01|NNNJ\xff\xff\xff\xffJ\xff"
        "\xff\xff\xffK?tb\x89]("
        "K\x00"
        "c__builtin__\nxrange\nK\x00M"s;
    p += static_cast<char>(n & 0xff);
    p += static_cast<char>(n >> 8);
    p += "\x86Rq\x01K\x01h\x01K\x02h\x01"
         "etb."s;
    return NpyHeaderOf("'|O'", "(3, 2)") + p;
  };
  const GroundTruthOptions o = Options(GroundTruthType::kVprBench, path);
  // 3 queries by 3 references: at most 3 + 64 = 67 indices a query, 1 + 3 x (2 + 67) = 208
  // values. 60 numbers named three times: 1 + 3 x (2 + 60) = 187, read.
  WriteBytes(path, rows_naming_one_range(60));
  const GroundTruth read = LoadQueryReference(o, 3, 3);
  EXPECT_EQ(read.matches, (Matches{{0, 1, 2}, {0, 1, 2}, {0, 1, 2}}));
  EXPECT_EQ(read.dropped, 3 * 57);
  // 67 numbers, as many as a query may list: read.
  WriteBytes(path, rows_naming_one_range(67));
  EXPECT_EQ(LoadQueryReference(o, 3, 3).dropped, 3 * 64);
  // Refused when the range is called, before its numbers are made: 1000 numbers, more than the
  // whole file may hold; 100, more than one query may list.
  WriteBytes(path, rows_naming_one_range(1000));
  ExpectInputError([&] { LoadQueryReference(o, 3, 3); },
                   {"VPR-Bench ground truth " + Q(path) + ": REDUCE at byte ",
                    ": the range objects make 1000 numbers in all; expected at most 208 (3 "
                    "queries listing at most 67 reference indices each: the 3 reference frames "
                    "up to the run's last, and 64 more)"});
  WriteBytes(path, rows_naming_one_range(100));
  ExpectInputError([&] { LoadQueryReference(o, 3, 3); },
                   {"VPR-Bench ground truth " + Q(path) + ": REDUCE at byte ",
                    ": range(0, 100, 1) makes 100 numbers; expected at most 67 in one list (3 "
                    "queries listing at most 67"});
  // With a range of frames (Initial_image), the file's rows are those its header gives, and a
  // list may name every frame up to the run's last from the traversal's start: 5 + 3 + 64.
  GroundTruthOptions ranged = o;
  ranged.first_frame = 5;
  WriteBytes(path, rows_naming_one_range(70));
  EXPECT_EQ(LoadQueryReference(ranged, 3, 3).dropped, 3 * 70);  // rows 0-2 are before frame 5
  WriteBytes(path, rows_naming_one_range(100));
  ExpectInputError([&] { LoadQueryReference(ranged, 3, 3); },
                   {": range(0, 100, 1) makes 100 numbers; expected at most 72 in one list (3 "
                    "queries listing at most 72 reference indices each: the 8 reference frames"});
}

}  // namespace
}  // namespace openable
