// Test_OpenABLE runs with the match score, Sequence_partial, SAD, contrast enhancement and
// descriptor fusion: their files against the tested library pieces, and their evaluation
// against the independent numpy reference (tests/tools/evaluate_reference.py) on real data.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "matching/contrast.h"
#include "matching/normalize.h"
#include "matching/sequence.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

// The bundled sample: 300 summer frames (reference) then 300 winter frames (queries).
std::vector<std::string> Sample(const std::string& descriptor, int length) {
  return {"--quiet",
          "--set",
          "Images_path=" + testing::SampleDir() + "/summer",
          "--set",
          "Images_path_2=" + testing::SampleDir() + "/winter",
          "--set",
          "Image_descriptor=" + descriptor,
          "--set",
          "Image_sequences=" + std::to_string(length),
          "--set",
          "Npy_name=m.npy"};
}

cv::Mat1f RunMatrix(const std::string& dir, std::vector<std::string> args) {
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  EXPECT_EQ(o.status, 0) << o.err;
  return ReadNpy(dir + "/m.npy");
}

const std::vector<int> kStarts = {0, 300};

// Fusion: the matrix of HOG+LDB with weights 1 and 0.5 is the sum of the single-frame
// matrices of the single runs (each M' = D / max D), weighted, summed along sequences and
// divided by its largest value.
TEST(Fusion, IsTheWeightedSumOfTheSingleRuns) {
  const std::string dir = testing::TempDir();
  const cv::Mat1f hog = RunMatrix(dir, Sample("HOG", 1));
  const cv::Mat1f ldb = RunMatrix(dir, Sample("LDB", 1));
  std::vector<std::string> fused = Sample("HOG+LDB", 5);
  fused.insert(fused.end(), {"--set", "Fusion_weights=1,0.5"});
  const Outcome o = RunProgram(testing::TestOpenableExe(), fused, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const cv::Mat1f got = ReadNpy(dir + "/m.npy");
  ASSERT_EQ(got.size(), cv::Size(600, 600));
  cv::Mat1f expected = hog + 0.5 * ldb;
  SequenceDistancesInPlace(expected, 5, kStarts, kStarts);
  NormalizeByMax(expected);
  EXPECT_LE(cv::norm(got, expected, cv::NORM_INF), 2e-5);
  // The weights matter: equal weights give another matrix.
  fused.back() = "Fusion_weights=1,1";
  EXPECT_GT(cv::norm(RunMatrix(dir, fused), got, cv::NORM_INF), 1e-3);
}

// SAD with contrast enhancement (L = 1): the single-frame SAD matrix enhanced as
// matching/contrast.h does (tested against a naive loop), then divided by its largest value.
// The z-scores do not depend on the scale, so enhancing M' = D / max D gives the same matrix.
TEST(SeqSlamBaseline, SadWithContrastEnhancementIsTheEnhancedSadMatrix) {
  const std::string dir = testing::TempDir();
  const cv::Mat1f sad = RunMatrix(dir, Sample("SAD", 1));
  std::vector<std::string> args = Sample("SAD", 1);
  args.insert(args.end(), {"--set", "Contrast_enhancement=1", "--set", "Contrast_window=10"});
  const cv::Mat1f got = RunMatrix(dir, args);
  cv::Mat1f expected = sad.clone();
  EnhanceContrast(expected, 10, kStarts);
  NormalizeByMax(expected);
  EXPECT_LE(cv::norm(got, expected, cv::NORM_INF), 1e-4);
  // SeqSLAM finds the seasons' diagonal on the sample (chance: 5 / 300).
  for (std::string& a : args)
    if (a == "Image_sequences=1") a = "Image_sequences=10";
  const cv::Mat1f seq = RunMatrix(dir, args);
  const double r1 = AlignedRecallAt1(seq, 300, 0, 300, 2);
  std::cout << "[ sample ] SAD + contrast enhancement, L = 10: R@1 (+-2) = " << r1 << "\n";
  EXPECT_GT(r1, 0.5);
}

// Sequence_partial skip: the first L - 1 frames of each traversal have no sequence; their
// cells are +inf in the .npy, the largest value (1) in the text file, and the evaluation counts
// the queries without an answer.
TEST(SequencePartial, SkippedCellsInEveryExport) {
  const std::string dir = testing::TempDir();
  std::vector<std::string> args = Sample("LDB", 10);
  args.insert(args.end(), {"--set", "Sequence_partial=skip", "--set", "Txt_name=m.txt", "--set",
                           "Ground_truth_type=aligned", "--set", "Evaluation_name=eval"});
  args.erase(args.begin());  // not --quiet: the report is read below
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const cv::Mat1f m = ReadNpy(dir + "/m.npy");
  ASSERT_EQ(m.rows, 600);
  std::istringstream txt(ReadAll(dir + "/m.txt"));
  int empty = 0;
  for (int i = 0; i < 600; ++i)
    for (int j = 0; j < 600; ++j) {
      float v = 0;
      ASSERT_TRUE(static_cast<bool>(txt >> v));
      const bool expect_empty = i % 300 < 9 || j % 300 < 9;  // along diagonals, L = 10
      ASSERT_EQ(std::isinf(m(i, j)) && m(i, j) > 0, expect_empty) << i << "," << j;
      ASSERT_FALSE(std::isnan(m(i, j))) << i << "," << j;
      if (expect_empty) {
        ++empty;
        ASSERT_EQ(v, 1.0f) << i << "," << j;
      } else {
        ASSERT_NEAR(v, m(i, j), 1e-6);
      }
    }
  EXPECT_NE(o.out.find(std::to_string(empty) + " cells without a value"), std::string::npos)
      << o.out;
  const Json evaluation = ReadJson(dir + "/eval.json");
  const Json& run = evaluation.at("runs").at(0);
  EXPECT_EQ(RunFigure(run, "unanswered_queries"), 9);
  EXPECT_EQ(run.at("layout").at("queries"), 300);
  // openable_evaluate reads the NaN cells back as cells without a value.
  const Outcome e = RunProgram(testing::OpenableEvaluateExe(),
                               {"--matrix", "m.npy", "--reference-frames", "300", "--gt-type",
                                "aligned", "--output", "again"},
                               dir);
  ASSERT_EQ(e.status, 0) << e.err;
  const Json again = ReadJson(dir + "/again.json");
  EXPECT_EQ(RunFigure(again.at("runs").at(0), "auc"), RunFigure(run, "auc"));
}

// The ratio score on the sample (two traversals) and the skip rule, against the reference.
TEST(MatchScore, RatioEvaluationOfTheSampleAgreesWithTheReference) {
  const std::string dir = testing::TempDir();
  std::vector<std::string> args = Sample("HOG", 10);
  args.insert(args.end(), {"--set", "Match_score=ratio", "--set", "Match_score_window=7", "--set",
                           "Sequence_partial=skip", "--set", "Ground_truth_type=aligned", "--set",
                           "Evaluation_name=eval", "--set", "Match_threshold=0.8"});
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const Json settings = ReadJson(dir + "/eval.json").at("settings");
  EXPECT_EQ(settings.at("match_score"), "ratio");
  EXPECT_EQ(settings.at("match_score_window"), 7);
  CheckAgainstReference(dir, {"--reference-frames", "300", "--aligned", "--tolerance", "2",
                              "--score", "ratio", "--score-window", "7"});
}

// Loop closure on a real indoor sequence that goes round twice (84 frames, 1-based pairs):
// the ratio's candidates and rivals are the frames at least Exclusion frames back.
TEST(MatchScore, RatioLoopClosureOnRtabmapAgreesWithTheReference) {
  const std::string data = testing::DatasetsDir() + "/rtabmap_samples";
  OPENABLE_REQUIRE_PATH(data);
  EvaluateAgainstTheReference(
      {"Images_path=" + data + "/images", "Image_sequences=3", "Npy_name=m.npy",
       "Ground_truth_type=pairs", "Ground_truth=" + data + "/ground_truth_pairs.txt",
       "Ground_truth_base=1", "Exclusion=10", "Tolerance=1", "Match_score=ratio",
       "Match_score_window=3", "Evaluation_name=eval"},
      {"--pairs", data + "/ground_truth_pairs.txt", "--base", "1", "--exclusion", "10",
       "--tolerance", "1", "--score", "ratio", "--score-window", "3"});
}

// The report counts the best matches that Match_threshold accepts, by the chosen score.
TEST(MatchScore, ReportCountsTheAcceptedBestMatches) {
  const std::string dir = testing::TempDir();
  std::vector<std::string> args = Sample("HOG", 10);
  args.erase(args.begin());
  args.insert(args.end(), {"--set", "Match_score=ratio", "--set", "Match_threshold=0.9"});
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  // Count independently: each winter frame's best summer frame and its ratio (window 10).
  const cv::Mat1f m = ReadNpy(dir + "/m.npy");
  const int accepted = AcceptedByRatio(m, 300, 300, 10, 0.9f);
  EXPECT_NE(o.out.find("accepted: " + std::to_string(accepted) +
                       " of 300 best matches with "
                       "ratio score <= 0.9 (Match_threshold)"),
            std::string::npos)
      << o.out;
}

}  // namespace
}  // namespace openable
