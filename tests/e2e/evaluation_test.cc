// End-to-end evaluation: Test_OpenABLE with ground truth, openable_evaluate on saved
// matrices, every input error of the issue, and the figures on real datasets checked against
// the independent numpy implementation in tests/tools/evaluate_reference.py.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>

#include "OpenABLE/io/json.h"
#include "OpenABLE/io/npy.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

std::string SampleConfig(const std::string& dir, const std::string& extra) {
  const std::string path = dir + "/Config.txt";
  std::ofstream(path) << "Images_path: \"" << testing::SampleDir() << "/summer\"\n"
                      << "Images_path_2: \"" << testing::SampleDir() << "/winter\"\n"
                      << "Npy_name: \"out/matrix.npy\"\n"
                      << "Image_sequences: 10\n"
                      << extra;
  return path;
}

TEST(Evaluation, SampleRunAgainstAlignedTruthWritesEveryFile) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(
      testing::TestOpenableExe(),
      {SampleConfig(dir, "Ground_truth_type: aligned\nTolerance: 2\nEvaluation_name: out/eval\n"),
       "--quiet"},
      dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("AUC"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("ABLE AP"), std::string::npos) << o.out;
  for (const char* f :
       {"eval.json", "eval_per_query.csv", "eval_ablep.csv", "eval_pr.png", "eval_overlay.png"})
    EXPECT_TRUE(fs::exists(dir + "/out/" + f)) << f;

  // R@1 computed here from the matrix, by brute force, against the JSON.
  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 600);
  const double r1 = AlignedRecallAt1(m, 300, 0, 300, 2);
  const Json evaluation = ReadJson(dir + "/out/eval.json");
  const Json& per_query = evaluation.at("runs").at(0).at("per_query");
  EXPECT_NEAR(per_query.at("recall_at_1").get<double>(), r1, 1e-6);
  EXPECT_EQ(per_query.at("positive_queries"), 300);
  // Every winter frame is positive, so the last point of the curve accepts all 300 answers:
  // its recall is R@1 again and its precision too.
  std::istringstream csv(ReadAll(dir + "/out/eval_per_query.csv"));
  std::string line, last;
  std::getline(csv, line);
  EXPECT_EQ(line, "threshold,precision,recall,f1,tp,fp");
  while (std::getline(csv, line)) last = line;
  double thr, p, r;
  ASSERT_EQ(std::sscanf(last.c_str(), "%lf,%lf,%lf", &thr, &p, &r), 3) << last;
  EXPECT_NEAR(r, r1, 1e-6);
  EXPECT_NEAR(p, r1, 1e-6);
  // The ABLE-P curve has 100 thresholds k / 99.
  std::istringstream able(ReadAll(dir + "/out/eval_ablep.csv"));
  int lines = 0;
  while (std::getline(able, line)) ++lines;
  EXPECT_EQ(lines, 101);
  const cv::Mat plot = cv::imread(dir + "/out/eval_pr.png");
  EXPECT_GT(plot.cols, 600);
  const cv::Mat overlay = cv::imread(dir + "/out/eval_overlay.png");
  EXPECT_GE(overlay.cols, 300);
}

TEST(Evaluation, OpenableEvaluateComparesRunsInOneFigureAndAgreesWithTheRun) {
  const std::string dir = testing::TempDir();
  const std::string config =
      SampleConfig(dir, "Ground_truth_type: aligned\nEvaluation_name: out/run\n");
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(), {config, "--quiet"}, dir).status, 0);
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(),
                       {config, "--quiet", "--set", "Image_descriptor=HOG", "--set",
                        "Npy_name=out/hog.npy", "--set", "Evaluation_name="},
                       dir)
                .status,
            0);
  const Outcome o = RunProgram(
      testing::OpenableEvaluateExe(),
      {"--matrix", "out/matrix.npy", "--label", "LDB", "--matrix", "out/hog.npy", "--label", "HOG",
       "--reference-frames", "300", "--gt-type", "aligned", "--output", "out/cmp"},
      dir);
  ASSERT_EQ(o.status, 0) << o.err;
  for (const char* f : {"cmp.json", "cmp_pr.png", "cmp_LDB_per_query.csv", "cmp_HOG_per_query.csv",
                        "cmp_LDB_overlay.png", "cmp_HOG_ablep.csv"})
    EXPECT_TRUE(fs::exists(dir + "/out/" + f)) << f;
  const Json run = ReadJson(dir + "/out/run.json"), cmp = ReadJson(dir + "/out/cmp.json");
  // The run's figures are those of the comparison's first run (LDB); the second is HOG.
  ASSERT_EQ(cmp.at("runs").size(), 2u);
  for (const char* key : {"auc", "recall_at_100p", "max_f1", "recall_at_1", "recall_at_10",
                          "average_precision_percent"})
    EXPECT_EQ(RunFigure(run.at("runs").at(0), key), RunFigure(cmp.at("runs").at(0), key)) << key;
  EXPECT_EQ(cmp.at("runs").at(1).at("label"), "HOG");
}

// In a run: Evaluation_protocol all adds the two tables' rows and the two curve files to the
// evaluation's files, and the JSON records the protocols.
TEST(Evaluation, RunWithEveryProtocolWritesTheirCurves) {
  const std::string dir = testing::TempDir();
  const Outcome o =
      RunProgram(testing::TestOpenableExe(),
                 {SampleConfig(dir,
                               "Ground_truth_type: aligned\nEvaluation_protocol: all\n"
                               "Evaluation_name: out/eval\n"),
                  "--quiet"},
                 dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("vpr_tutorial    "), std::string::npos) << o.out;
  for (const char* f :
       {"eval.json", "eval_vpr_bench.csv", "eval_vpr_tutorial.csv", "eval_per_query.csv"})
    EXPECT_TRUE(fs::exists(dir + "/out/" + f)) << f;
  const Json evaluation = ReadJson(dir + "/out/eval.json");
  EXPECT_EQ(evaluation.at("settings").at("protocols"), "openable,vpr_bench,vpr_tutorial");
  // 300 winter queries, each with its summer frame: VPR-Bench and VPR_Tutorial count them all.
  EXPECT_EQ(evaluation.at("runs").at(0).at("vpr_bench").at("queries_with_truth"), 300);
}

// A saved square matrix of queries x references scored three ways in one table, against
// VPR-Bench's own ground-truth file: the figures of VPR-Bench's and VPR_Tutorial's code
// (tests/data/reference_protocols/expected.json, made by their metric functions), each
// protocol's row in the table, and the curve files.
TEST(Evaluation, OpenableEvaluateScoresAMatrixAsVprBenchAndVprTutorialDo) {
  const std::string dir = testing::TempDir();
  const std::string data = testing::SourceDir() + "/tests/data/reference_protocols/";
  const Outcome o =
      RunProgram(testing::OpenableEvaluateExe(),
                 {"--matrix", data + "gardens_point_hog.npy", "--label", "HOG", "--layout",
                  "query_reference", "--gt-type", "vpr_bench", "--ground-truth",
                  data + "vpr_bench_gardens_point_ground_truth_new.npy", "--tolerance", "0",
                  "--protocol", "all", "--output", "out/e"},
                 dir);
  ASSERT_EQ(o.status, 0) << o.err;
  for (const char* row : {"HOG                openable", "HOG                vpr_bench",
                          "HOG                vpr_tutorial"})
    EXPECT_NE(o.out.find(row), std::string::npos) << row << "\n" << o.out;
  EXPECT_NE(o.out.find("3 ground-truth pairs dropped"), std::string::npos) << o.out;
  const Json evaluation = ReadJson(dir + "/out/e.json");
  const Json expected = ReadJson(data + "expected.json");
  const Json& run = evaluation.at("runs").at(0);
  ASSERT_TRUE(run.contains("vpr_bench")) << run.dump();
  ASSERT_TRUE(run.contains("vpr_tutorial")) << run.dump();
  for (const char* key : {"auc_pr", "extended_precision", "recall_at_100p"})
    EXPECT_NEAR(run.at("vpr_bench").at(key).get<double>(),
                expected.at("real").at("vpr_bench").at(key).get<double>(), 1e-8)
        << key;
  EXPECT_NEAR(run.at("vpr_tutorial").at("multi").at("auc").get<double>(),
              expected.at("real").at("vpr_tutorial").at("auc_multi").get<double>(), 1e-8);
  EXPECT_EQ(evaluation.at("settings").at("protocols"), "openable,vpr_bench,vpr_tutorial");
  // The curves: VPR-Bench's points, then VPR_Tutorial's 101 multi- and 101 single-match ones.
  const std::string bench_csv = ReadAll(dir + "/out/e_vpr_bench.csv");
  EXPECT_EQ(bench_csv.rfind("precision,recall\n", 0), 0u);
  const std::string tutorial_csv = ReadAll(dir + "/out/e_vpr_tutorial.csv");
  EXPECT_EQ(std::count(tutorial_csv.begin(), tutorial_csv.end(), '\n'), 1 + 101 + 101);
  EXPECT_EQ(tutorial_csv.find("single,"), tutorial_csv.find("\nsingle,") + 1);
}

// A similarity given where distances are expected: OpenABLE's HOG matrix of Gardens Point
// turned into 1 - M ranks each query's least similar place first (AUC near 0). openable_evaluate
// says in one line, on stderr and under its table, that the ranking looks reversed, with the
// AUC of the reversed matrix, which is the AUC of M itself (evaluated here separately).
TEST(Evaluation, OpenableEvaluateWarnsWhenTheMatrixLooksLikeASimilarity) {
  const std::string dir = testing::TempDir();
  const std::string data = testing::SourceDir() + "/tests/data/reference_protocols/";
  const cv::Mat1f m = DecodeNpyMatrix(ReadAll(data + "gardens_point_hog.npy"), "m");
  const cv::Mat1f similarity = 1.0f - m;
  testing::WriteBytes(dir + "/similarity.npy", EncodeNpy(similarity));
  const std::vector<std::string> truth = {
      "--layout",       "query_reference",
      "--gt-type",      "vpr_bench",
      "--ground-truth", data + "vpr_bench_gardens_point_ground_truth_new.npy",
      "--tolerance",    "0",
      "--json"};
  std::vector<std::string> args = {"--matrix", data + "gardens_point_hog.npy"};
  args.insert(args.end(), truth.begin(), truth.end());
  const Outcome plain = RunProgram(testing::OpenableEvaluateExe(), args, dir);
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(plain.err.find("warning"), std::string::npos) << plain.err;
  // The AUC of a run of the --json report (ProgramJson, OpenABLE/app/run_report.cc).
  const auto auc_of = [](const std::string& report) {
    return RunFigure(Json::parse(report).at("evaluation").at("runs").at(0), "auc").get<double>();
  };
  const double auc = auc_of(plain.out);
  ASSERT_GT(auc, 0.25);

  args = {"--matrix", "similarity.npy"};
  args.insert(args.end(), truth.begin(), truth.end());
  const Outcome reversed = RunProgram(testing::OpenableEvaluateExe(), args, dir);
  ASSERT_EQ(reversed.status, 0) << reversed.err;
  const double reversed_auc = auc_of(reversed.out);
  EXPECT_LT(reversed_auc, 0.1);
  char expected[160];
  std::snprintf(expected, sizeof expected,
                "openable_evaluate: warning: similarity: the ranking looks reversed: per-query "
                "AUC %.3f with the smallest values as best matches, %.3f with the largest",
                reversed_auc, auc);
  EXPECT_NE(reversed.err.find(expected), std::string::npos) << expected << "\n" << reversed.err;
  EXPECT_TRUE(OneLine(reversed.err)) << reversed.err;
  // The table says it too.
  args.pop_back();
  const Outcome table = RunProgram(testing::OpenableEvaluateExe(), args, dir);
  EXPECT_NE(table.out.find("  warning: the ranking looks reversed"), std::string::npos)
      << table.out;
}

// A ground truth with no true place among the candidates: every pair of a loop-closure file
// lies within the exclusion window, so recall, AUC and R@N are 0 whatever the matrix; the run
// says so in one line on stderr and under its table, and still exits 0.
TEST(Evaluation, RunSaysWhenNoQueryHasATruePlace) {
  const std::string dir = testing::TempDir();
  testing::WriteBytes(dir + "/near.txt", "150,100\n200,160\n");  // 50 and 40 frames apart
  const Outcome o = RunProgram(
      testing::TestOpenableExe(),
      {SampleConfig(dir, "Ground_truth_type: pairs\nGround_truth: near.txt\nExclusion: 60\n"),
       "--quiet", "--set", "Images_path_2="},
      dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string line =
      "no query has a true place among its candidates (240 queries; 2 pairs of the ground truth "
      "over the evaluated block, 2 of them closer than the exclusion (60 frames))";
  EXPECT_NE(o.err.find("Test_OpenABLE: warning: evaluation: " + line), std::string::npos) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.out.find("  warning: " + line), std::string::npos) << o.out;
}

// A saved matrix remembers its run's settings (out/matrix.npy.json): openable_evaluate given
// the matrix alone (no ground-truth type, no reference frames, no score) gives the run's own
// figures; a setting given on the command line overrides the remembered one, a note says so,
// and the figures are then those of a run made with that setting.
TEST(Evaluation, SavedMatrixIsEvaluatedWithItsRunsSettingsUnlessOverridden) {
  const std::string dir = testing::TempDir();
  const std::string config =
      SampleConfig(dir,
                   "Ground_truth_type: aligned\nEvaluation_name: out/run\nMatch_score: ratio\n"
                   "Match_threshold: 0.9\nMatch_consistency: 1\nTolerance: 3\n");
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(), {config, "--quiet"}, dir).status, 0);
  ASSERT_TRUE(fs::exists(dir + "/out/matrix.npy.json"));
  const Outcome o = RunProgram(testing::OpenableEvaluateExe(),
                               {"--matrix", "out/matrix.npy", "--output", "out/later"}, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.err.find("openable_evaluate: note: evaluated with the settings the matrix's run "
                       "had (out/matrix.npy.json): "),
            std::string::npos)
      << o.err;
  const Json run = ReadJson(dir + "/out/run.json"), later = ReadJson(dir + "/out/later.json");
  const Json &run_run = run.at("runs").at(0), &later_run = later.at("runs").at(0);
  for (const char* key : {"auc", "recall_at_100p", "max_f1", "recall_at_1", "recall_at_10",
                          "accepted", "average_precision_percent"})
    EXPECT_EQ(RunFigure(run_run, key), RunFigure(later_run, key)) << key;
  EXPECT_EQ(run.at("settings").at("tolerance"), later.at("settings").at("tolerance"));
  EXPECT_EQ(later.at("settings").at("match_score"), "ratio") << later.dump();

  // Overridden: the figures of a run made with the distance score, and a note.
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(),
                       {config, "--quiet", "--set", "Match_score=distance", "--set",
                        "Match_threshold=-1", "--set", "Match_consistency=0", "--set",
                        "Npy_name=out/distance.npy", "--set", "Evaluation_name=out/distance"},
                       dir)
                .status,
            0);
  const Outcome d = RunProgram(
      testing::OpenableEvaluateExe(),
      {"--matrix", "out/matrix.npy", "--set", "Match_score=distance", "--set", "Match_threshold=-1",
       "--set", "Match_consistency=0", "--output", "out/overridden"},
      dir);
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_NE(d.err.find("openable_evaluate: note: Match_score \"distance\" as given here, not "
                       "\"ratio\" as the matrix's run had it (out/matrix.npy.json)"),
            std::string::npos)
      << d.err;
  const Json distance = ReadJson(dir + "/out/distance.json");
  const Json overridden = ReadJson(dir + "/out/overridden.json");
  const Json& distance_run = distance.at("runs").at(0);
  for (const char* key : {"auc", "recall_at_100p", "max_f1", "recall_at_1"})
    EXPECT_EQ(RunFigure(distance_run, key), RunFigure(overridden.at("runs").at(0), key)) << key;
  EXPECT_NE(RunFigure(distance_run, "auc"), RunFigure(run_run, "auc"));
}

// Settings files that cannot be used: matrices whose runs disagree on a setting the command
// line does not give, the thresholded matrix M'', a file that is not such a file. One line,
// status 1, nothing written.
TEST(Evaluation, SavedMatrixSettingsThatCannotBeUsedAreRefused) {
  const std::string dir = testing::TempDir();
  const std::string config = SampleConfig(
      dir, "Ground_truth_type: aligned\nTxt_name: \"out/thresholded.txt\"\nThreshold: 0.2\n");
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(), {config, "--quiet"}, dir).status, 0);
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(),
                       {config, "--quiet", "--set", "Tolerance=5", "--set",
                        "Npy_name=out/other.npy", "--set", "Txt_name="},
                       dir)
                .status,
            0);
  const auto refused = [&](const std::vector<std::string>& args, const std::string& expect) {
    std::vector<std::string> all = args;
    all.insert(all.end(), {"--output", "out/none"});
    const Outcome o = RunProgram(testing::OpenableEvaluateExe(), all, dir);
    EXPECT_EQ(o.status, 1) << o.err;
    EXPECT_TRUE(OneLine(o.err)) << o.err;
    EXPECT_NE(o.err.find(expect), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir + "/out/none.json"));
  };
  refused({"--matrix", "out/matrix.npy", "--matrix", "out/other.npy"},
          "openable_evaluate: error: --matrix \"out/other.npy\": its run had Tolerance \"5\" "
          "(out/other.npy.json), the run of out/matrix.npy.json had \"2\"; expected one value: "
          "give --set Tolerance=VALUE for all");
  refused({"--matrix", "out/thresholded.txt"},
          "--matrix \"out/thresholded.txt\": holds the thresholded matrix M'' of Eq. 9");
  std::ofstream(dir + "/out/matrix.npy.json") << "[1, 2]";
  refused({"--matrix", "out/matrix.npy"},
          "settings of the matrix \"out/matrix.npy.json\": no \"evaluation_keys\" object");
  // Given on the command line, the disagreeing setting is one value for both: evaluated.
  fs::remove(dir + "/out/matrix.npy.json");
  const Outcome o = RunProgram(testing::OpenableEvaluateExe(),
                               {"--matrix", "out/matrix.npy", "--matrix", "out/other.npy",
                                "--tolerance", "4", "--reference-frames", "300"},
                               dir);
  EXPECT_EQ(o.status, 0) << o.err;
}

// A settings file that does not fit its matrix is refused in one line naming both sizes: one
// written beside another run's matrix, and files edited within their own sizes (whose numbers
// no longer hold together). Otherwise the evaluation would read another block of the matrix
// (a wrong reference_frames) without a word.
TEST(Evaluation, SavedMatrixSettingsThatDoNotFitTheirMatrixAreRefused) {
  const std::string dir = testing::TempDir();
  const std::string config = SampleConfig(dir, "Ground_truth_type: aligned\n");
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(), {config, "--quiet"}, dir).status, 0);
  // 80 frames of one traversal: an 80 x 80 matrix and its settings.
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(),
                       {config, "--quiet", "--set", "Images_path_2=", "--set", "Final_image=80",
                        "--set", "Exclusion=10", "--set", "Ground_truth_type=none", "--set",
                        "Npy_name=out/small.npy"},
                       dir)
                .status,
            0);
  const std::string settings = dir + "/out/matrix.npy.json";
  const std::string original = ReadAll(settings);
  const openable::Json written = openable::Json::parse(original);
  ASSERT_EQ(written["rows"], 600);
  ASSERT_EQ(written["reference_frames"], 300);
  const auto refused = [&](const std::string& expect) {
    const Outcome o = RunProgram(testing::OpenableEvaluateExe(),
                                 {"--matrix", "out/matrix.npy", "--output", "out/none"}, dir);
    EXPECT_EQ(o.status, 1) << o.err;
    EXPECT_TRUE(OneLine(o.err)) << o.err;
    EXPECT_NE(o.err.find(expect), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir + "/out/none.json"));
  };
  const auto edited = [&](const std::function<void(openable::Json&)>& edit) {
    openable::Json j = written;
    edit(j);
    std::ofstream(settings) << j.dump();
  };
  // Beside another run's matrix.
  fs::copy_file(dir + "/out/small.npy.json", settings, fs::copy_options::overwrite_existing);
  refused(
      "matrix \"out/matrix.npy\": 600x600, but its settings file \"out/matrix.npy.json\" "
      "was written with a 80x80 matrix (traversals of 80 frames)");
  // Edited: the first traversal made shorter, the reference frames with it (500 frames in all).
  edited([](openable::Json& j) {
    j["traversals"][0]["frames"] = 200;
    j["reference_frames"] = 200;
    j["python_evaluate"]["reference_frames"] = 200;
  });
  refused(
      "a 600x600 matrix of 500 frames in all; expected a square matrix of as many rows as "
      "frames");
  // Edited: the reference frames alone.
  edited([](openable::Json& j) { j["reference_frames"] = 200; });
  refused(
      "\"reference_frames\" 200 with 2 traversals; expected 300 (the first traversal's "
      "frames)");
  // Edited: the reference frames of Python's keywords alone.
  edited([](openable::Json& j) { j["python_evaluate"]["reference_frames"] = 100; });
  refused("\"python_evaluate\" has reference_frames 100, the file 300; expected one value");
  // Edited: sizes that agree with each other but not with the matrix.
  edited([](openable::Json& j) {
    j["rows"] = j["cols"] = 400;
    j["traversals"][0]["frames"] = j["traversals"][1]["frames"] = 200;
    j["reference_frames"] = j["python_evaluate"]["reference_frames"] = 200;
  });
  refused(
      "matrix \"out/matrix.npy\": 600x600, but its settings file \"out/matrix.npy.json\" "
      "was written with a 400x400 matrix (traversals of 200 and 200 frames)");
  // Edited: a frame range that cannot hold the traversals' frames.
  edited([](openable::Json& j) { j["evaluation_keys"]["Final_image"] = "100"; });
  refused(
      "a traversal of 300 frames within Initial_image 0 and Final_image 100; expected at "
      "most 100");
  // Restored: evaluated.
  std::ofstream(settings) << original;
  const Outcome o = RunProgram(testing::OpenableEvaluateExe(), {"--matrix", "out/matrix.npy"}, dir);
  EXPECT_EQ(o.status, 0) << o.err;
}

// Bad evaluation inputs: status 1, one line naming the file or key, nothing written.
struct BadTruth {
  const char* name;
  std::vector<std::string> args;
  std::string expect;
};
void PrintTo(const BadTruth& c, std::ostream* os) { *os << c.name; }

class BadTruthInputs : public ::testing::TestWithParam<BadTruth> {};

TEST_P(BadTruthInputs, OneLineNonZeroExitNoOutput) {
  const std::string dir = testing::TempDir();
  {
    std::ofstream m(dir + "/m.txt");  // a 20 x 20 distance matrix
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 20; ++j) m << std::abs(i - j) << (j < 19 ? " " : "\n");
    }
    std::ofstream(dir + "/gt5.txt") << "0 1 0 0 0\n1 0 0 0 0\n0 0 0 0 0\n0 0 0 0 0\n0 0 0 0 0\n";
    std::ofstream(dir + "/far.csv") << "3,1\n25,2\n";
    std::ofstream(dir + "/xy.csv") << "0,0\n1,0\n2,0\n";
    std::ofstream(dir + "/near.csv") << "3,1\n";
    // A pickle (protocol 2) that would call posix.system("touch pwned") if unpickled.
    const std::string pickle(
        "\x80\x02"
        "cposix\nsystem\n"
        "X\x0b\x00\x00\x00touch pwned"
        "\x85R.",
        35);
    std::ofstream(dir + "/evil.npy", std::ios::binary) << NpyHeaderOf("'|O'", "(10, 2)") << pickle;
    std::ofstream(dir + "/numeric.npy", std::ios::binary) << EncodeNpy(cv::Mat1f(3, 4, 1.f));
  }
  std::vector<std::string> args = {"--matrix", "m.txt", "--output", "out/e"};
  args.insert(args.end(), GetParam().args.begin(), GetParam().args.end());
  const Outcome o = RunProgram(testing::OpenableEvaluateExe(), args, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find(GetParam().expect), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out")) << "output left behind";
  EXPECT_FALSE(fs::exists(dir + "/pwned")) << "a pickled call ran";
}

INSTANTIATE_TEST_SUITE_P(
    Errors, BadTruthInputs,
    ::testing::Values(
        BadTruth{
            "MatrixOfWrongSize", {"--gt-type", "matrix", "--ground-truth", "gt5.txt"}, "gt5.txt"},
        BadTruth{
            "PairOutsideTheRun", {"--gt-type", "pairs", "--ground-truth", "far.csv"}, "far.csv"},
        BadTruth{"MissingFile", {"--gt-type", "pairs", "--ground-truth", "nope.csv"}, "nope.csv"},
        BadTruth{"NegativeTolerance", {"--gt-type", "aligned", "--tolerance", "-1"}, "Tolerance"},
        BadTruth{"ZeroRadius",
                 {"--gt-type", "positions", "--ground-truth", "xy.csv", "--radius", "0"},
                 "Ground_truth_radius"},
        BadTruth{"AlignedOnOneSequence", {"--gt-type", "aligned"}, "aligned"},
        BadTruth{"HeadingWithoutOrientation",
                 {"--gt-type", "positions", "--ground-truth", "xy.csv", "--heading", "45"},
                 "Ground_truth_heading"},
        BadTruth{"PositionsDoNotCoverTheRun",
                 {"--gt-type", "positions", "--ground-truth", "xy.csv"},
                 "xy.csv"},
        BadTruth{"UnknownType", {"--gt-type", "gps"}, "Ground_truth_type"},
        BadTruth{"NegativeVicinity",
                 {"--gt-type", "aligned", "--reference-frames", "10", "--vicinity", "-2"},
                 "Vicinity"},
        BadTruth{"ReferenceProtocolOnOneSequence",
                 {"--gt-type", "pairs", "--ground-truth", "near.csv", "--protocol", "vpr_bench"},
                 "Evaluation_protocol: vpr_bench needs two traversals"},
        BadTruth{"UnknownProtocol",
                 {"--gt-type", "aligned", "--reference-frames", "10", "--protocol", "recall"},
                 "Evaluation_protocol: \"recall\" is not valid"},
        BadTruth{
            "PickleThatRunsCode",
            {"--gt-type", "vpr_bench", "--reference-frames", "10", "--ground-truth", "evil.npy"},
            "posix.system"},
        BadTruth{
            "NumericMatrixAsVprBenchFile",
            {"--gt-type", "vpr_bench", "--reference-frames", "10", "--ground-truth", "numeric.npy"},
            "numeric.npy"},
        BadTruth{"SoftGroundTruthOfAnotherType",
                 {"--gt-type", "aligned", "--reference-frames", "10", "--ground-truth-soft",
                  "numeric.npy"},
                 "Ground_truth_soft"},
        BadTruth{"TutorialMatrixOfWrongSize",
                 {"--gt-type", "vpr_tutorial", "--reference-frames", "10", "--ground-truth",
                  "numeric.npy"},
                 "expected 10x10"}));

// --- Real data, checked against the independent numpy implementation -------------------------

TEST(EvaluationOnDatasets, NordlandWinterAgainstSummer) {
  const std::string data = testing::DatasetsDir() + "/nordland_trimmed";
  OPENABLE_REQUIRE_PATH(data);
  const std::string dir = EvaluateAgainstTheReference(
      {"Images_path=" + data + "/summer", "Images_path_2=" + data + "/winter", "Image_sequences=10",
       "Npy_name=m.npy", "Ground_truth_type=aligned", "Tolerance=2", "Evaluation_name=eval"},
      {"--reference-frames", "1788", "--aligned", "--tolerance", "2"});
  EXPECT_GE(RunFigure(ReadJson(dir + "/eval.json").at("runs").at(0), "recall_at_1").get<double>(),
            0.355);
}

TEST(EvaluationOnDatasets, GardensPointDayRightAgainstDayLeft) {
  const std::string data = testing::DatasetsDir() + "/gardens_point";
  OPENABLE_REQUIRE_PATH(data);
  EvaluateAgainstTheReference(
      {"Images_path=" + data + "/day_left", "Images_path_2=" + data + "/day_right",
       "Image_sequences=5", "Npy_name=m.npy", "Ground_truth_type=aligned", "Evaluation_name=eval"},
      {"--reference-frames", "200", "--aligned", "--tolerance", "2"});
}

TEST(EvaluationOnDatasets, Kitti00LoopsFromPosesAgainstTheLoopList) {
  const std::string data = testing::DatasetsDir() + "/kitti00_first1700";
  OPENABLE_REQUIRE_PATH(data);
  // Loops derived here from the poses; the reference reads them from loop_gt_5m.txt instead.
  EvaluateAgainstTheReference(Kitti00LoopSettings(data, 1),
                              {"--pairs", data + "/loop_gt_5m.txt", "--max-col4", "45",
                               "--exclusion", "100", "--tolerance", "3"});
}

}  // namespace
}  // namespace openable
