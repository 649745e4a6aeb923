// The presets of config/presets/ run end to end on the bundled sample as a user runs them
// (Test_OpenABLE <preset> --set Images_path=...), and what they report is checked against the
// matrix they wrote.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

std::string Preset(const std::string& name) {
  return testing::SourceDir() + "/config/presets/" + name + ".txt";
}

// Test_OpenABLE run quietly in `dir` as a user runs a preset: Test_OpenABLE <preset> --set ...
Outcome RunPreset(const std::string& name, const std::string& dir,
                  const std::vector<std::string>& settings) {
  return RunProgram(testing::TestOpenableExe(), QuietArgs(settings, {Preset(name)}), dir);
}

// Two traversals of 300 frames (summer reference, winter queries) with the frame alignment as
// ground truth: the settings the preset's comment announces are in effect, R@1 of the report is
// that of the written matrix, and the accepted best matches are those whose ratio to the best
// match outside +-10 frames is at most 0.9 and that an independent query confirms.
TEST(Presets, AcrossConditionsRunsOnTheSample) {
  const std::string dir = testing::TempDir();
  const Outcome o =
      RunPreset("across_conditions", dir,
                {"Images_path=" + testing::SampleDir() + "/summer",
                 "Images_path_2=" + testing::SampleDir() + "/winter", "Ground_truth_type=aligned",
                 "Npy_name=m.npy", "Png_name=m.png", "Evaluation_name=eval"});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("HOG ("), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(" + LDB ("), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("sequence length 40"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("score ratio (window +-10)"), std::string::npos) << o.out;
  for (const char* f : {"m.npy", "m.png", "eval.json", "eval_pr.png", "eval_overlay.png"})
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;

  const cv::Mat1f m = ReadNpy(dir + "/m.npy");
  ASSERT_EQ(m.size(), cv::Size(600, 600));
  const Json evaluation = ReadJson(dir + "/eval.json");
  const Json& per_query = evaluation.at("runs").at(0).at("per_query");
  EXPECT_NEAR(per_query.at("recall_at_1").get<double>(), AlignedRecallAt1(m, 300, 0, 300, 2), 1e-9);
  // Accepted: ratio <= 0.9 and confirmed by an independent query's best match
  // (Match_consistency 1, L = 40); the confirmation refuses some the ratio alone accepts.
  const std::vector<bool> confirmed = AgreeingByBruteForce(m, 300, 300, 300, 40);
  const int accepted = AcceptedByRatio(m, 300, 300, 10, 0.9f, &confirmed);
  EXPECT_NE(o.out.find("accepted: " + std::to_string(accepted) + " of 300 best matches"),
            std::string::npos)
      << o.out;
  EXPECT_LT(accepted, AcceptedByRatio(m, 300, 300, 10, 0.9f));
  // On the sample as on the datasets it was chosen on, what it accepts is right.
  EXPECT_EQ(per_query.at("accepted").at("precision"), 1.0) << evaluation.dump();
  EXPECT_GT(accepted, 100);
}

// One traversal (the 300 summer frames) without ground truth: the loop-closure preset writes
// the matrix of SIFT with sequences of 5 frames, verifies its candidates and says so.
TEST(Presets, LoopClosureRunsOnTheSample) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunPreset(
      "loop_closure", dir,
      {"Images_path=" + testing::SampleDir() + "/summer", "Npy_name=m.npy", "Png_name=m.png"});
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("SIFT ("), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("sequence length 5"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("score distance"), std::string::npos) << o.out;
  // The preset verifies its loops (20 candidates per query, ORB features).
  EXPECT_NE(o.out.find("verification: ORB"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("20 candidates per query"), std::string::npos) << o.out;
  const cv::Mat1f m = ReadNpy(dir + "/m.npy");
  ASSERT_EQ(m.size(), cv::Size(300, 300));
  double max = 0;
  cv::minMaxLoc(m, nullptr, &max);
  EXPECT_FLOAT_EQ(static_cast<float>(max), 1.0f);  // Eq. 5
  EXPECT_TRUE(fs::exists(dir + "/m.png"));
}

// Every preset, and the example config/Config.txt, is a complete configuration: it loads and
// holds every key the program knows, with the value in effect (no key missing or unknown).
TEST(Presets, AreCompleteConfigurations) {
  for (const std::string& name : {Preset("across_conditions"), Preset("loop_closure"),
                                  Preset("auto"), testing::SourceDir() + "/config/Config.txt"}) {
    const Outcome o =
        RunProgram(testing::TestOpenableExe(), {name, "--print-config"}, testing::TempDir());
    ASSERT_EQ(o.status, 0) << name << o.err;
    const std::string text = ReadAll(name);
    // Every key the program knows appears in the preset.
    std::size_t keys = 0;
    for (std::size_t p = o.out.find("\n", 0); p != std::string::npos; p = o.out.find("\n", p + 1)) {
      const std::size_t colon = o.out.find(": ", p + 1);
      const std::size_t next = o.out.find("\n", p + 1);
      if (colon == std::string::npos || next == std::string::npos || colon > next) continue;
      if (o.out[p + 1] == '#') continue;
      const std::string line = o.out.substr(p + 1, next - p - 1);
      EXPECT_NE(text.find("\n" + line + "\n"), std::string::npos) << name << ": " << line;
      ++keys;
    }
    EXPECT_GT(keys, 100u) << name;
  }
}

}  // namespace
}  // namespace openable
