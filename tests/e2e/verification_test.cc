// Geometric verification on real frames: KITTI 00's revisit (frames 1555-1644 coming back over
// 100-199), as one short sequence. The loops file is read back and its answers scored here,
// independently of the evaluation, and the online detector must give the batch run's loops.
#include <map>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "OpenABLE/app/run.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/online/online.h"
#include "config/config.h"
#include "tests/e2e/e2e_support.h"

namespace openable {
namespace {

using e2e::Outcome;
using e2e::RunProgram;
namespace fs = std::filesystem;

constexpr int kExclusion = 50, kTolerance = 3;

// A folder of links: KITTI frames 100-199 as 0-99, then 1555-1644 as 100-189; and the pairs of
// loop_gt_5m.txt with headings within 45 degrees, in those numbers ("later,earlier").
struct Revisit {
  std::string folder, pairs;
  std::map<int, std::vector<int>> truth;  // frame -> true earlier frames (the pairs file)
  std::vector<cv::Point2d> position;      // ground-plane (x, z) position of each frame
};

Revisit MakeRevisit(const std::string& dir) {
  const std::string kitti = testing::DatasetsDir() + "/kitti00_first1700";
  Revisit r;
  r.folder = dir + "/frames";
  fs::create_directories(r.folder);
  auto number = [](int kitti_frame) {
    return kitti_frame < 1000 ? kitti_frame - 100 : kitti_frame - 1555 + 100;
  };
  auto add = [&](int from, int to) {
    for (int f = from; f <= to; ++f) {
      char source[32], link[32];
      std::snprintf(source, sizeof source, "/image_0/%06d.png", f);
      std::snprintf(link, sizeof link, "/%04d.png", number(f));
      fs::create_symlink(kitti + source, r.folder + link);
    }
  };
  add(100, 199);
  add(1555, 1644);
  std::ifstream in(kitti + "/loop_gt_5m.txt");
  std::ostringstream pairs;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    int j = 0, i = 0;
    double distance = 0, heading = 0;
    std::istringstream(line) >> j >> i >> distance >> heading;
    if (heading >= 45 || j < 1555 || j > 1644 || i < 100 || i > 199) continue;
    pairs << number(j) << "," << number(i) << "\n";
    r.truth[number(j)].push_back(number(i));
  }
  std::ifstream poses(kitti + "/poses/00_first1700.txt");
  std::vector<cv::Point2d> all;
  while (std::getline(poses, line)) {
    double p[12];
    std::istringstream fields(line);
    for (double& x : p) fields >> x;
    all.emplace_back(p[3], p[11]);
  }
  for (int f = 100; f <= 199; ++f) r.position.push_back(all.at(f));
  for (int f = 1555; f <= 1644; ++f) r.position.push_back(all.at(f));
  r.pairs = dir + "/pairs.csv";
  std::ofstream(r.pairs) << pairs.str();
  return r;
}

std::vector<std::string> RunArgs(const Revisit& r, const std::string& dir) {
  return {testing::SourceDir() + "/config/Config.txt",
          "--set",
          "Images_path=" + r.folder,
          "--set",
          "Images_path_2=",
          "--set",
          "Txt_name=",
          "--set",
          "Npy_name=",
          "--set",
          "Png_name=",
          "--set",
          "Threshold=-1",
          "--set",
          "Image_descriptor=LDB",
          "--set",
          "Image_sequences=1",
          "--set",
          "Ground_truth_type=pairs",
          "--set",
          "Ground_truth=" + r.pairs,
          "--set",
          "Ground_truth_base=0",
          "--set",
          "Exclusion=" + std::to_string(kExclusion),
          "--set",
          "Tolerance=" + std::to_string(kTolerance),
          "--set",
          "Verification=1",
          "--set",
          "Loops_name=" + dir + "/loops.csv",
          "--set",
          "Evaluation_name=" + dir + "/e"};
}

struct LoopLine {
  int query, reference, rank, inliers, geometric, verified;
};

std::vector<LoopLine> ReadLoops(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "query,reference,rank,distance,score,matches,inliers,model,geometric,streak,verified");
  std::vector<LoopLine> out;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream s(line);
    for (std::string x; std::getline(s, x, ',');) f.push_back(x);
    EXPECT_EQ(f.size(), 11u) << line;
    if (f.size() != 11) continue;
    out.push_back({std::stoi(f[0]), std::stoi(f[1]), std::stoi(f[2]), std::stoi(f[6]),
                   std::stoi(f[8]), std::stoi(f[10])});
  }
  return out;
}

TEST(Verification, LoopsFileAgreesWithTheEvaluationOnKittiRevisit) {
  OPENABLE_REQUIRE_PATH(testing::DatasetsDir() + "/kitti00_first1700/image_0");
  const std::string dir = testing::TempDir();
  const Revisit r = MakeRevisit(dir);
  const Outcome o = RunProgram(testing::TestOpenableExe(), RunArgs(r, dir), dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::vector<LoopLine> loops = ReadLoops(dir + "/loops.csv");
  ASSERT_FALSE(loops.empty());
  // Each query's answer: its first verified line (lines are in rank order).
  std::map<int, int> answer;
  std::map<int, int> last_rank;
  for (const LoopLine& l : loops) {
    EXPECT_GT(l.rank, last_rank[l.query]) << "ranks in order";
    last_rank[l.query] = l.rank;
    EXPECT_GE(l.geometric, l.verified);
    if (l.geometric) {
      EXPECT_GE(l.inliers, 40);  // Verification_min_inliers
    }
    if (l.verified && !answer.count(l.query)) answer[l.query] = l.reference;
  }
  int tp = 0, fp = 0, positives = 0;
  std::vector<int> wrong;
  for (int q = kExclusion; q < 190; ++q) {
    std::vector<int> candidates_truth;
    for (int t : r.truth.count(q) ? r.truth.at(q) : std::vector<int>())
      if (t <= q - kExclusion) candidates_truth.push_back(t);
    positives += candidates_truth.empty() ? 0 : 1;
    if (!answer.count(q)) continue;
    bool correct = false;
    for (int t : candidates_truth) correct = correct || std::abs(t - answer[q]) <= kTolerance;
    (correct ? tp : fp) += 1;
    if (cv::norm(r.position[q] - r.position[answer[q]]) > 30) wrong.push_back(q);
  }
  ASSERT_GT(positives, 50);
  const Json evaluation = e2e::ReadJson(dir + "/e.json");
  const Json& run = evaluation.at("runs").at(0);
  ASSERT_TRUE(run.contains("per_query")) << run.dump();
  ASSERT_TRUE(run.contains("per_query_unverified")) << run.dump();
  // The figures of the verified answers.
  const Json& final_figures = run.at("per_query");
  const Json& accepted = final_figures.at("accepted");
  EXPECT_EQ(final_figures.at("positive_queries"), positives);
  EXPECT_EQ(accepted.at("matches"), tp + fp);
  EXPECT_NEAR(accepted.at("recall").get<double>(), static_cast<double>(tp) / positives, 1e-6);
  EXPECT_NEAR(accepted.at("precision").get<double>(),
              tp + fp > 0 ? static_cast<double>(tp) / (tp + fp) : 1.0, 1e-6);
  EXPECT_EQ(final_figures.at("unanswered_queries"),
            (190 - kExclusion) - static_cast<int>(answer.size()));
  // What verification is for: every accepted loop shows the same street, within 30 m in the
  // ground truth (two frames of a street share their view over that range: frames 50-99 drive
  // on along frames 0-49's street, and the turn into the revisit sees the street ahead); at the
  // evaluation's 5 m the precision stays high, and most revisits are found.
  for (const int q : wrong) ADD_FAILURE() << "a loop farther than 30 m at frame " << q;
  EXPECT_GE(static_cast<double>(tp) / (tp + fp), 0.9);
  EXPECT_GE(tp, positives / 2);
  EXPECT_NE(o.out.find("+ verification"), std::string::npos) << o.out;
  EXPECT_TRUE(fs::exists(dir + "/e_overlay.png"));
}

TEST(Verification, OnlineDetectorGivesTheBatchRunsLoops) {
  OPENABLE_REQUIRE_PATH(testing::DatasetsDir() + "/kitti00_first1700/image_0");
  const std::string dir = testing::TempDir();
  const Revisit r = MakeRevisit(dir);
  Config config = LoadConfig(testing::SourceDir() + "/config/Config.txt");
  const std::vector<std::string> args = RunArgs(r, dir);
  for (std::size_t i = 2; i + 1 < args.size(); i += 2) ApplyOverride(config, args[i]);
  config.evaluation.truth.type = GroundTruthType::kNone;
  config.evaluation.name.clear();
  config.output.loops_name.clear();
  std::ostringstream sink;
  ProgressReporter quiet(sink, false, false);
  const RunOutcome batch = openable::Run(config, quiet, [](const std::string&) {});
  ASSERT_TRUE(batch.verification);

  OnlineOptions options;
  options.descriptor.name = "LDB";
  options.exclusion = kExclusion;
  options.score.window = config.matching.score.window;
  options.verification = config.verification;
  options.verification.tolerance = kTolerance;
  OnlineDetector detector(options);
  const std::vector<std::string> files = ListImages(r.folder, "png");
  std::map<int, const QueryVerification*> by_query;
  for (const QueryVerification& q : batch.verification->queries) by_query[q.query] = &q;
  int compared = 0, verified = 0;
  for (int f = 0; f < static_cast<int>(files.size()); ++f) {
    const OnlineResult online = detector.AddFrame(ReadImageFile(files[f]));
    if (!by_query.count(f)) {
      EXPECT_TRUE(online.candidates.empty()) << "frame " << f;
      continue;
    }
    const QueryVerification& q = *by_query[f];
    ASSERT_EQ(online.candidates.size(), q.candidates.size()) << "frame " << f;
    for (std::size_t c = 0; c < q.candidates.size(); ++c) {
      EXPECT_EQ(online.candidates[c].frame, q.candidates[c].reference) << "frame " << f;
      EXPECT_EQ(online.candidates[c].inliers, q.candidates[c].check.inliers) << "frame " << f;
      EXPECT_EQ(online.candidates[c].verified, q.candidates[c].accepted) << "frame " << f;
      verified += online.candidates[c].verified ? 1 : 0;
      ++compared;
    }
  }
  EXPECT_EQ(compared, batch.verification->pairs);
  EXPECT_GT(verified, 20);
}

// The bounded mode verifies the candidates among its kept matches: each query's best match
// (rank 1) is the dense run's, with the same checks.
TEST(Verification, BoundedModeChecksTheSameBestMatches) {
  OPENABLE_REQUIRE_PATH(testing::DatasetsDir() + "/kitti00_first1700/image_0");
  const std::string dir = testing::TempDir();
  const Revisit r = MakeRevisit(dir);
  // One candidate per query (rank 1 is what is compared): half the time of five.
  std::vector<std::string> dense = RunArgs(r, dir);
  dense.insert(dense.end(), {"--set", "Verification_candidates=1"});
  ASSERT_EQ(RunProgram(testing::TestOpenableExe(), dense, dir).status, 0);
  fs::rename(dir + "/loops.csv", dir + "/dense.csv");
  std::vector<std::string> bounded = RunArgs(r, dir);
  for (const char* a : {"Matrix_mode=2", "Best_matches=50",
                        "Evaluation_name=", "Ground_truth_type=", "Verification_candidates=1"})
    bounded.insert(bounded.end(), {"--set", a});
  bounded.insert(bounded.end(), {"--set", "Matches_name=" + dir + "/matches.csv"});
  const Outcome o = RunProgram(testing::TestOpenableExe(), bounded, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  auto best = [](const std::vector<LoopLine>& lines) {
    std::map<int, std::pair<int, int>> out;  // query -> (reference, inliers) of rank 1
    for (const LoopLine& l : lines)
      if (l.rank == 1) out[l.query] = {l.reference, l.inliers};
    return out;
  };
  const auto a = best(ReadLoops(dir + "/dense.csv")), b = best(ReadLoops(dir + "/loops.csv"));
  EXPECT_EQ(a.size(), 190u - kExclusion);
  EXPECT_EQ(a, b);
}

TEST(Verification, RefusedSettingsNameTheKeyAndWriteNothing) {
  OPENABLE_REQUIRE_PATH(testing::DatasetsDir() + "/kitti00_first1700/image_0");
  const std::string dir = testing::TempDir();
  const Revisit r = MakeRevisit(dir);
  const std::string kitti = testing::DatasetsDir() + "/kitti00_first1700";
  struct Case {
    std::vector<std::string> extra;
    std::string key;
  };
  const std::vector<Case> cases = {
      // Full-size KITTI intrinsics on the half-size frames.
      {{"--set", "Verification_calibration=" + kitti + "/calib.txt"}, "Verification_calibration"},
      {{"--set", "Verification_consistency=500"}, "Verification_consistency"},
      {{"--set", "Verification_max_features=0"}, "Verification_max_features"},
      {{"--set", "Verification_calibration=" + dir + "/none.txt"}, "Verification_calibration"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args = RunArgs(r, dir);
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
    EXPECT_EQ(o.status, 1) << c.key;
    EXPECT_TRUE(e2e::OneLine(o.err)) << o.err;
    EXPECT_NE(o.err.find(c.key), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir + "/loops.csv")) << c.key;
    EXPECT_FALSE(fs::exists(dir + "/e.json")) << c.key;
  }
  // The half-size calibration fits, and gives the essential matrix.
  std::vector<std::string> args = RunArgs(r, dir);
  for (const std::string& a :
       {std::string("--set"), "Verification_calibration=" + kitti + "/calib.txt",
        std::string("--set"), std::string("Verification_calibration_scale=0.5"),
        std::string("--set"), std::string("Verification_candidates=1")})
    args.push_back(a);
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.out.find("essential matrix"), std::string::npos) << o.out;
  EXPECT_NE(e2e::ReadAll(dir + "/loops.csv").find(",essential,"), std::string::npos);
  // A run without queries (every frame within Exclusion of the first) and the consistency off
  // is not refused: it verifies nothing.
  std::vector<std::string> none = RunArgs(r, dir);
  for (const char* a :
       {"Exclusion=500", "Verification_consistency=0", "Ground_truth_type=", "Evaluation_name="})
    none.insert(none.end(), {"--set", a});
  const Outcome empty = RunProgram(testing::TestOpenableExe(), none, dir);
  ASSERT_EQ(empty.status, 0) << empty.err;
  EXPECT_NE(empty.out.find("0 queries, 0 candidates checked"), std::string::npos) << empty.out;
}

TEST(Verification, VideoFramesCannotBeReadAgain) {
  const std::string dir = testing::TempDir();
  const std::string video = dir + "/v.avi";
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, cv::Size(64, 48),
                           false);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 120; ++i) writer.write(cv::Mat1b(48, 64, static_cast<uchar>(2 * i)));
  }
  const Outcome o =
      RunProgram(testing::TestOpenableExe(),
                 {testing::SourceDir() + "/config/Config.txt", "--set", "Frame_mode=1", "--set",
                  "Video_path_1=" + video, "--set", "Verification=1", "--set",
                  "Txt_name=" + dir + "/m.txt", "--set", "Npy_name=", "--set", "Png_name=", "--set",
                  "Evaluation_name=", "--set", "Ground_truth_type="},
                 dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_TRUE(e2e::OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("Verification: 1"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("video"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir + "/m.txt"));
}

}  // namespace
}  // namespace openable
