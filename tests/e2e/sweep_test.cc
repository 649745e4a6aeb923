// openable_sweep on the bundled sample: each run's figures equal those of the same single run
// of Test_OpenABLE, the ranking follows the chosen figure, frames are described once per
// description setting, and bad --vary values stop it before any work with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/io/json.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

std::vector<std::string> SampleArgs() {
  return {testing::SourceDir() + "/config/Config.txt",
          "--quiet",
          "--set",
          "Images_path=" + testing::SampleDir() + "/summer",
          "--set",
          "Images_path_2=" + testing::SampleDir() + "/winter",
          "--set",
          "Ground_truth_type=aligned",
          "--set",
          "Evaluation_name=",
          "--set",
          "Txt_name=",
          "--set",
          "Npy_name=",
          "--set",
          "Png_name="};
}

std::vector<std::string> With(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// openable_sweep run in `dir` on the sample (SampleArgs) with the arguments `more`.
Outcome RunSweep(const std::string& dir, const std::vector<std::string>& more) {
  return RunProgram(testing::OpenableSweepExe(), With(SampleArgs(), more), dir);
}

// The sweep run whose varied settings are `settings` ({"Key": "value", ...} in the order of the
// --vary options); null when absent.
Json SweepRun(const Json& sweep, const Json& settings) {
  for (const Json& run : sweep.at("runs"))
    if (run.at("settings") == settings) return run;
  return Json();
}

// `key`'s figure of each run of the sweep document, in the order the runs are listed (best
// first): "rank", or a figure of the run's evaluation (RunFigure).
std::vector<double> RankedFigures(const Json& sweep, const std::string& key) {
  std::vector<double> out;
  for (const Json& run : sweep.at("runs"))
    out.push_back((key == "rank" ? run.at("rank") : RunFigure(run, key)).get<double>());
  return out;
}

TEST(Sweep, FiguresEqualTheSingleRunsAndAreRanked) {
  const std::string dir = testing::TempDir();
  const Outcome sweep =
      RunSweep(dir, {"--vary", "Image_descriptor=LDB,HOG", "--vary", "Image_sequences=1,5",
                     "--vary", "Match_score=distance,ratio", "--output", "out/sweep"});
  ASSERT_EQ(sweep.status, 0) << sweep.err;
  const Json json = ReadJson(dir + "/out/sweep.json");
  ASSERT_FALSE(json.at("runs").empty());
  EXPECT_TRUE(fs::exists(dir + "/out/sweep_pr.png"));
  // Frames described once per descriptor, not once per combination, and read once for both.
  EXPECT_EQ(json.at("descriptions"), 2);
  EXPECT_EQ(json.at("frame_reads"), 1);

  const char* metrics[] = {"auc",
                           "recall_at_100p",
                           "max_f1",
                           "recall_at_1",
                           "recall_at_5",
                           "average_precision_percent",
                           "unanswered_queries"};
  int compared = 0;
  for (const std::string d : {"LDB", "HOG"})
    for (const std::string l : {"1", "5"})
      for (const std::string s : {"distance", "ratio"}) {
        const Json run =
            SweepRun(json, {{"Image_descriptor", d}, {"Image_sequences", l}, {"Match_score", s}});
        ASSERT_FALSE(run.is_null()) << d << " " << l << " " << s;
        const Outcome single = RunProgram(
            testing::TestOpenableExe(),
            With(SampleArgs(), {"--set", "Image_descriptor=" + d, "--set", "Image_sequences=" + l,
                                "--set", "Match_score=" + s, "--set", "Evaluation_name=one"}),
            dir);
        ASSERT_EQ(single.status, 0) << single.err;
        const Json one = ReadJson(dir + "/one.json");
        for (const char* m : metrics) {
          const Json& want = RunFigure(one.at("runs").at(0), m);
          ASSERT_TRUE(want.is_number()) << m << ": " << want.dump();
          EXPECT_EQ(RunFigure(run, m), want) << d << " L=" << l << " " << s << ": " << m;
        }
        ++compared;
      }
  EXPECT_EQ(compared, 8);

  // Ranked by AUC, best first, ranks 1..8 in order; the CSV has the same rows.
  const std::vector<double> ranks = RankedFigures(json, "rank");
  ASSERT_FALSE(ranks.empty());
  for (std::size_t i = 0; i < ranks.size(); ++i) EXPECT_EQ(ranks[i], static_cast<double>(i + 1));
  const std::vector<double> aucs = RankedFigures(json, "auc");
  ASSERT_EQ(aucs.size(), 8u);
  EXPECT_TRUE(std::is_sorted(aucs.rbegin(), aucs.rend()));
  std::istringstream csv(ReadAll(dir + "/out/sweep.csv"));
  std::string line;
  int rows = 0;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("rank,Image_descriptor,Image_sequences,Match_score,label,auc,", 0), 0u)
      << line;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 8);
  // The table on stdout says what it is ranked by.
  EXPECT_NE(sweep.out.find("ranked by AUC"), std::string::npos) << sweep.out;
}

TEST(Sweep, RanksByTheChosenFigure) {
  const std::string dir = testing::TempDir();
  const Outcome sweep = RunSweep(dir, {"--vary", "Image_sequences=1,3,5", "--rank-by",
                                       "recall_at_1", "--best", "2", "--output", "r"});
  ASSERT_EQ(sweep.status, 0) << sweep.err;
  const Json json = ReadJson(dir + "/r.json");
  const std::vector<double> r1 = RankedFigures(json, "recall_at_1");
  ASSERT_EQ(r1.size(), 3u);
  EXPECT_TRUE(std::is_sorted(r1.rbegin(), r1.rend()));
  EXPECT_EQ(json.at("descriptions"), 1);
}

// Bad sweeps: one line naming the option, key and value, exit 1, nothing written, and no run
// started (the checks come before the first frame is read).
TEST(Sweep, BadValuesStopBeforeAnyWork) {
  const std::string dir = testing::TempDir();
  const BadArgs cases[] = {
      {{"--vary", "Imge_sequences=1,5"}, {"--vary", "Imge_sequences", "Image_sequences"}},
      {{"--vary", "Image_sequences=1,0"}, {"--vary", "Image_sequences", "\"0\""}},
      {{"--vary", "Image_sequences=1,,5"}, {"--vary", "Image_sequences", "empty value"}},
      {{"--vary", "Image_sequences=1,1"}, {"Image_sequences", "\"1\"", "twice"}},
      {{"--vary", "Match_score=distance,ratoi"}, {"Match_score", "ratoi", "distance or ratio"}},
      {{"--vary", "Image_descriptor=LDB,HOG+LDBX"}, {"Image_descriptor", "LDBX"}},
      {{"--vary", "Txt_name=a,b"}, {"--vary", "Txt_name", "cannot be varied"}},
      {{"--vary", "Image_sequences"}, {"--vary", "Image_sequences", "Key=v1,v2"}},
      {{"--vary", "Image_sequences=1,5", "--vary", "Image_sequences=10"},
       {"Image_sequences", "twice"}},
      {{}, {"--vary", "none given"}},
      {{"--vary", "Match_score=distance,ratio", "--set", "Match_score_window=400"},
       {"Match_score=ratio", "Match_score_window", "400"}},
      {{"--vary", "Image_sequences=1,5", "--set", "Ground_truth_type="},
       {"Ground_truth_type", "empty"}},
      {{"--vary", "Image_sequences=1,5", "--set", "Matrix_mode=2", "--set", "Matches_name=m.csv"},
       {"Matrix_mode", "2", "dense"}},
      {{"--vary", "Image_sequences=1,5", "--best", "0"}, {"--best", "\"0\""}},
      {{"--vary", "Image_sequences=1,5", "--rank-by", "speed"}, {"--rank-by", "speed", "auc"}},
      {{"--vary", "Image_descriptor=LDB,HOG+LDB", "--set", "Image_sequences=2"},
       {"Image_descriptor=HOG+LDB", "Fusion_weights"}},
  };
  for (const BadArgs& c : cases) {
    fs::remove_all(dir + "/bad");
    const Outcome o = RunSweep(dir, With({"--output", "bad/sweep"}, c.args));
    std::string what;
    for (const auto& a : c.args) what += a + " ";
    EXPECT_EQ(o.status, 1) << what << o.err;
    EXPECT_TRUE(OneLine(o.err)) << what << o.err;
    for (const auto& part : c.parts)
      EXPECT_NE(o.err.find(part), std::string::npos) << what << ": " << part << " in " << o.err;
    EXPECT_EQ(o.err.find("run 1 of"), std::string::npos) << what;
    EXPECT_FALSE(fs::exists(dir + "/bad")) << what;
    EXPECT_TRUE(o.out.empty()) << what << o.out;
  }
  // A usage error (an option without its value) exits 2.
  const Outcome usage = RunProgram(testing::OpenableSweepExe(), {"x.txt", "--vary"}, dir);
  EXPECT_EQ(usage.status, 2) << usage.err;
  EXPECT_NE(usage.err.find("--vary needs a value"), std::string::npos) << usage.err;
}

}  // namespace
}  // namespace openable
