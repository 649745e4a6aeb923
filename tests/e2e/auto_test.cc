// The auto mode (Auto 1, config/presets/auto.txt) end to end: the run with the chosen settings
// is the run a user gets by writing those settings into the configuration, byte for byte; the
// criteria it reports are those of the matrix it wrote; unrelated traversals are judged
// unreliable and nothing is accepted; bad candidate lists are one line before any work; on a
// night-like pair of real frames the choice is within 0.02 of the best AUC a sweep finds with
// ground truth, and every match it accepts is right.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/image/robustness.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/io/json.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

std::string AutoPreset() { return testing::SourceDir() + "/config/presets/auto.txt"; }

std::vector<std::string> Words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// The consistency of a written matrix's query-reference block by brute force
// (AgreeingByBruteForce, e2e_support.h).
double BruteConsistency(const cv::Mat1f& m, int references, int L) {
  const std::vector<bool> a =
      AgreeingByBruteForce(m, references, m.rows - references, references, L);
  return static_cast<double>(std::count(a.begin(), a.end(), true)) / a.size();
}

// The first 200 frames of each traversal of the sample (a shorter run under the sanitizers).
std::vector<std::string> SampleArgs() {
  return {"--quiet",
          "--set",
          "Final_image=200",
          "--set",
          "Images_path=" + testing::SampleDir() + "/summer",
          "--set",
          "Images_path_2=" + testing::SampleDir() + "/winter",
          "--set",
          "Ground_truth_type=aligned",
          "--set",
          "Npy_name=out/m.npy",
          "--set",
          "Png_name=out/m.png",
          "--set",
          "Txt_name=out/m.txt",
          "--set",
          "Evaluation_name=out/eval"};
}

TEST(Auto, TheRunOfTheChoiceIsThePlainRunOfItsSettingsByteForByte) {
  const std::string dir = testing::TempDir();
  std::vector<std::string> args = {AutoPreset()};
  for (const std::string& a : SampleArgs()) args.push_back(a);
  args.push_back("--json");
  const Outcome automatic = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(automatic.status, 0) << automatic.err;
  const std::string json = automatic.out;
  const Json report = Json::parse(json);
  const Json& choice = report.at("auto");
  const std::string chosen = choice.at("chosen").get<std::string>();
  ASSERT_FALSE(chosen.empty()) << json;
  EXPECT_EQ(choice.at("reliable"), true) << json;
  EXPECT_EQ(choice.at("criterion"), "agreement");
  // Every candidate of the default list is there, each with its criteria.
  const Json& candidates = choice.at("candidates");
  EXPECT_EQ(candidates.size(), 18u);
  for (const Json& c : candidates)
    for (const char* key : {"settings", "consistency", "distinctiveness", "agreement"})
      EXPECT_TRUE(c.contains(key)) << c.dump();

  // The same preset with Auto 0 and the chosen settings written in: the same files.
  const std::string plain_dir = testing::TempDir();
  std::vector<std::string> plain = {AutoPreset()};
  for (const std::string& a : SampleArgs()) plain.push_back(a);
  plain.insert(plain.end(), {"--set", "Auto=0"});
  for (const std::string& setting : Words(chosen)) plain.insert(plain.end(), {"--set", setting});
  const Outcome by_hand = RunProgram(testing::TestOpenableExe(), plain, plain_dir);
  ASSERT_EQ(by_hand.status, 0) << by_hand.err;
  for (const char* f : {"m.npy", "m.png", "m.txt", "eval.json", "eval_per_query.csv",
                        "eval_ablep.csv", "eval_pr.png", "eval_overlay.png"}) {
    const std::string a = ReadAll(dir + "/out/" + f), b = ReadAll(plain_dir + "/out/" + f);
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_TRUE(a == b) << f << " differs between the auto run and the plain run of " << chosen;
  }

  // The chosen candidate's consistency is that of the matrix written (computed here by brute
  // force), up to one query: the candidates are judged on the sums before Eq. 5.
  int L = 0;
  for (const std::string& setting : Words(chosen))
    if (setting.rfind("Image_sequences=", 0) == 0) L = std::stoi(setting.substr(16));
  ASSERT_GT(L, 0) << chosen;
  const cv::Mat1f m = ReadNpy(dir + "/out/m.npy");
  ASSERT_EQ(m.rows, 400);
  const auto rank1 = std::find_if(candidates.begin(), candidates.end(),
                                  [](const Json& c) { return c.at("rank") == 1; });
  ASSERT_NE(rank1, candidates.end()) << json;
  EXPECT_NEAR(rank1->at("consistency").get<double>(), BruteConsistency(m, 200, L), 1.0 / 200);
  // What it accepted is right on the sample.
  const Json& run = report.at("evaluation").at("runs").at(0);
  EXPECT_EQ(run.at("per_query").at("accepted").at("precision"), 1.0);
}

TEST(Auto, UnrelatedTraversalsAreUnreliableAndAcceptNothing) {
  // Summer frames 0-99 against winter frames 200-299 of the sample: no place in common.
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  const std::vector<std::string> summer = ListImages(testing::SampleDir() + "/summer", "");
  const std::vector<std::string> winter = ListImages(testing::SampleDir() + "/winter", "");
  for (int i = 0; i < 100; ++i) {
    fs::copy_file(summer[i], dir + "/a/" + fs::path(summer[i]).filename().string());
    fs::copy_file(winter[200 + i], dir + "/b/" + fs::path(winter[200 + i]).filename().string());
  }
  // With the page of the run and the matches file, without ground truth (the auto preset's
  // own case).
  const Outcome o =
      RunProgram(testing::TestOpenableExe(),
                 {AutoPreset(), "--quiet", "--set", "Images_path=a", "--set", "Images_path_2=b",
                  "--set", "Npy_name=out/m.npy", "--set", "Png_name=", "--set",
                  "Report_name=out/report.html", "--set", "Matches_name=out/matches.csv", "--json"},
                 dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const Json report = Json::parse(o.out);
  EXPECT_EQ(report.at("auto").at("reliable"), false) << o.out;
  EXPECT_EQ(report.at("accepted").at("queries"), 0) << o.out;
  EXPECT_TRUE(fs::exists(dir + "/out/m.npy"));  // the outputs are still written
  // The page says UNRELIABLE and accepts nothing; the matches file marks no best match.
  const std::string page = ReadAll(dir + "/out/report.html");
  EXPECT_NE(page.find("UNRELIABLE: the auto mode could not trust any candidate"),
            std::string::npos);
  EXPECT_NE(page.find("No match accepted: the auto mode could not trust"), std::string::npos);
  EXPECT_NE(page.find("<section id=\"auto\">"), std::string::npos);
  std::istringstream matches(ReadAll(dir + "/out/matches.csv"));
  std::string line;
  std::getline(matches, line);
  EXPECT_EQ(line, "query,reference,distance,rank,score,accepted,confirmed");
  int records = 0;
  while (std::getline(matches, line)) {
    ++records;
    EXPECT_EQ(line.substr(line.size() - 4), ",0,0") << line;
  }
  EXPECT_GT(records, 100);
  // One line says so.
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("no candidate is consistent enough to be trusted"), std::string::npos)
      << o.err;
  // Every candidate's consistency is low, far from the threshold.
  const Json& candidates = report.at("auto").at("candidates");
  EXPECT_FALSE(candidates.empty()) << o.out;
  for (const Json& c : candidates) EXPECT_LT(c.at("consistency").get<double>(), 0.3) << c.dump();
  // The text report names it.
  const Outcome text = RunProgram(testing::TestOpenableExe(),
                                  {AutoPreset(), "--quiet", "--set", "Images_path=a", "--set",
                                   "Images_path_2=b", "--set", "Npy_name=", "--set", "Png_name="},
                                  dir);
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("UNRELIABLE: no candidate is consistent enough"), std::string::npos)
      << text.out;
}

// Bad candidate lists and runs the auto mode cannot choose for: one line naming the key and the
// value, exit 1, nothing written.
TEST(Auto, BadCandidatesAndRunsAreOneLineBeforeAnyWork) {
  struct Case {
    std::vector<std::string> sets;
    std::vector<std::string> parts;
  } cases[] = {
      {{"Auto_candidates="}, {"Auto_candidates", "empty"}},
      {{"Auto_candidates=Image_descriptor=HOG | "}, {"Auto_candidates", "group 2 of 2", "empty"}},
      {{"Auto_candidates=Image_descriptor=HOG,FOO"}, {"Auto_candidates", "FOO"}},
      {{"Auto_candidates=Imge_descriptor=HOG"},
       {"Auto_candidates", "Imge_descriptor", "Image_descriptor"}},
      {{"Auto_candidates=Image_descriptor=HOG Exclusion=50"},
       {"Auto_candidates", "Exclusion", "one traversal"}},
      {{"Auto_candidates=Image_descriptor=HOG Match_threshold=0.5"},
       {"Auto_candidates", "Match_threshold", "does not change the matrix"}},
      {{"Auto_candidates=Image_descriptor=HOG,HOG"}, {"Auto_candidates", "twice"}},
      {{"Auto_candidates=Image_sequences=0"}, {"Auto_candidates", "Image_sequences", "\"0\""}},
      {{"Images_path_2="}, {"Auto: 1", "two traversals", "loop_closure"}},
      {{"Matrix_mode=2", "Matches_name=out/k.csv"}, {"Auto: 1", "dense", "Matrix_mode"}},
      {{"Auto_min_consistency=1.5"}, {"Auto_min_consistency", "1.5", "[0, 1]"}},
  };
  for (const Case& c : cases) {
    const std::string dir = testing::TempDir();
    std::vector<std::string> args = {
        AutoPreset(), "--quiet",
        "--set",      "Images_path=" + testing::SampleDir() + "/summer",
        "--set",      "Images_path_2=" + testing::SampleDir() + "/winter",
        "--set",      "Npy_name=out/m.npy",
        "--set",      "Png_name=out/m.png"};
    for (const std::string& s : c.sets) args.insert(args.end(), {"--set", s});
    const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
    EXPECT_EQ(o.status, 1) << c.sets.front() << ": " << o.err;
    EXPECT_TRUE(OneLine(o.err)) << c.sets.front() << ": " << o.err;
    for (const std::string& part : c.parts)
      EXPECT_NE(o.err.find(part), std::string::npos) << c.sets.front() << ": " << o.err;
    EXPECT_FALSE(fs::exists(dir + "/out")) << c.sets.front();
  }
}

// Night-like queries (made here from Gardens Point day_right: another viewpoint by a few per
// cent, light from one side, a dark sky, noise: NightOptions::Strong) against day_left (the
// other side of the path):
// the auto run's AUC is within 0.02 of the best AUC of its candidates, which a sweep finds with
// the ground truth, and every match it accepts is right.
TEST(Auto, NightLikeGardensPointIsWithinTheBestOfTheSweep) {
  OPENABLE_REQUIRE_PATH(testing::DatasetsDir() + "/gardens_point");
  // Frames at half size (480 x 270): the descriptors see 64 x 64 patches either way, and the
  // test reads every frame once per descriptor.
  const std::string dir = testing::TempDir();
  const std::string gp = testing::DatasetsDir() + "/gardens_point";
  fs::create_directories(dir + "/day");
  fs::create_directories(dir + "/night");
  int frame = 0;
  for (const std::string& file : ListImages(gp + "/day_left", "")) {
    cv::Mat half;
    cv::resize(cv::imread(file, cv::IMREAD_COLOR), half, cv::Size(480, 270), 0, 0, cv::INTER_AREA);
    ASSERT_TRUE(cv::imwrite(dir + "/day/" + fs::path(file).filename().string(), half));
  }
  for (const std::string& file : ListImages(gp + "/day_right", "")) {
    cv::Mat half, f, out;
    cv::resize(cv::imread(file, cv::IMREAD_COLOR), half, cv::Size(480, 270), 0, 0, cv::INTER_AREA);
    half.convertTo(f, CV_32FC3, 1.0 / 255);
    MakeNightLike(f, NightOptions::Strong(), NoiseState(2, 7, frame++))
        .convertTo(out, CV_8UC3, 255);
    ASSERT_TRUE(cv::imwrite(dir + "/night/" + fs::path(file).filename().string(), out));
  }
  const std::vector<std::string> pair = {"--quiet",
                                         "--set",
                                         "Images_path=day",
                                         "--set",
                                         "Images_path_2=night",
                                         "--set",
                                         "Ground_truth_type=aligned",
                                         "--set",
                                         "Tolerance=2",
                                         "--set",
                                         "Npy_name=",
                                         "--set",
                                         "Png_name=",
                                         "--set",
                                         "Evaluation_name="};
  std::vector<std::string> args = {AutoPreset()};
  args.insert(args.end(), pair.begin(), pair.end());
  args.push_back("--json");
  const Outcome automatic = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(automatic.status, 0) << automatic.err;
  const Json report = Json::parse(automatic.out);
  EXPECT_EQ(report.at("auto").at("reliable"), true);
  const Json& per_query = report.at("evaluation").at("runs").at(0).at("per_query");
  const double auc = per_query.at("auc").get<double>();
  ASSERT_TRUE(per_query.contains("accepted")) << automatic.out;
  EXPECT_EQ(per_query.at("accepted").at("precision"), 1.0) << automatic.out;

  // Every candidate, and more (SAD without contrast enhancement, the others with it), in one
  // sweep with the ground truth: the best AUC among them.
  std::vector<std::string> sweep = {AutoPreset(),
                                    "--set",
                                    "Auto=0",
                                    "--set",
                                    "Fusion_weights=1,1",
                                    "--output",
                                    "s",
                                    "--vary",
                                    "Image_descriptor=HOG,SIFT,LDB,HOG+LDB,SAD",
                                    "--vary",
                                    "Contrast_enhancement=0,1",
                                    "--vary",
                                    "Image_sequences=10,20,40"};
  sweep.insert(sweep.end(), pair.begin(), pair.end());
  const Outcome s = RunProgram(testing::OpenableSweepExe(), sweep, dir);
  ASSERT_EQ(s.status, 0) << s.err;
  const Json swept = ReadJson(dir + "/s.json");
  ASSERT_FALSE(swept.at("runs").empty());
  double best = 0;
  for (const Json& run : swept.at("runs"))
    best = std::max(best, RunFigure(run, "auc").get<double>());
  EXPECT_GE(auc, best - 0.02) << "auto " << auc << ", best of the sweep " << best;
}

// openable_sweep ranks by the criteria without ground truth, and refuses to when a run has
// fewer than two queries.
TEST(Auto, SweepRanksWithoutGroundTruthAndRefusesOneFrame) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(
      testing::OpenableSweepExe(),
      {AutoPreset(), "--quiet", "--set", "Auto=0", "--set",
       "Images_path=" + testing::SampleDir() + "/summer", "--set",
       "Images_path_2=" + testing::SampleDir() + "/winter", "--vary", "Image_descriptor=HOG,LDB",
       "--vary", "Image_sequences=1,20", "--rank-by", "agreement", "--output", "out/s"},
      dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("ranked by agreement (no ground truth)"), std::string::npos) << o.out;
  EXPECT_TRUE(fs::exists(dir + "/out/s.csv"));
  EXPECT_TRUE(fs::exists(dir + "/out/s.json"));
  EXPECT_FALSE(fs::exists(dir + "/out/s_pr.png"));  // no ground truth, no curve
  const Json swept = ReadJson(dir + "/out/s.json");
  std::vector<double> agreement;
  for (const Json& run : swept.at("runs"))
    agreement.push_back(run.at("unsupervised").at("agreement").get<double>());
  ASSERT_EQ(agreement.size(), 4u);
  EXPECT_TRUE(std::is_sorted(agreement.rbegin(), agreement.rend()));

  // One frame in each traversal: one query.
  fs::create_directories(dir + "/one_a");
  fs::create_directories(dir + "/one_b");
  const std::vector<std::string> summer = ListImages(testing::SampleDir() + "/summer", "");
  fs::copy_file(summer[0], dir + "/one_a/a.png");
  fs::copy_file(summer[1], dir + "/one_b/b.png");
  const Outcome one =
      RunProgram(testing::OpenableSweepExe(),
                 {AutoPreset(), "--quiet", "--set", "Auto=0", "--set", "Images_path=one_a", "--set",
                  "Images_path_2=one_b", "--set", "Match_score=distance", "--vary",
                  "Image_sequences=1,2", "--rank-by", "consistency", "--output", "out2/s"},
                 dir);
  EXPECT_EQ(one.status, 1) << one.err;
  EXPECT_TRUE(OneLine(one.err)) << one.err;
  EXPECT_NE(one.err.find("--rank-by consistency"), std::string::npos) << one.err;
  EXPECT_FALSE(fs::exists(dir + "/out2"));
}

}  // namespace
}  // namespace openable
