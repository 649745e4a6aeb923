// End-to-end runs of the Test_OpenABLE program: the files it writes, the figures in them, and
// every input error of the issue (one line, non-zero exit, no output left behind).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <sstream>
#include <string>

#include "OpenABLE/io/frame_source.h"
#include "config/config.h"
#include "matching/bounded.h"
#include "matching/matrix.h"
#include "matching/search/approximate.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

namespace fs = std::filesystem;

std::string SampleConfig(const std::string& dir, const std::string& extra = "") {
  const std::string path = dir + "/Config.txt";
  std::ofstream(path) << "%YAML:1.0\n"
                      << "Frame_mode: 0\n"
                      << "Images_path: \"" << testing::SampleDir() << "/summer\"\n"
                      << "Images_path_2: \"" << testing::SampleDir() << "/winter\"\n"
                      << "Txt_name: \"out/matrix.txt\"\n"
                      << "Npy_name: \"out/matrix.npy\"\n"
                      << "Png_name: \"out/matrix.png\"\n"
                      << "Matrix_color: 4\n"
                      << "Image_descriptor: LDB\n"
                      << "Image_sequences: 10\n"
                      << "Threshold: 0.3\n"
                      << extra;
  return path;
}

// Approximate_search with the default engine, auto, builds the index it stands for (IVF for
// binary rows, HNSW for float rows): the kept matches are those of a run naming that engine,
// and the report names the index.
TEST(TestOpenABLE, ApproximateRunWithTheAutoEngineUsesAndNamesTheResolvedIndex) {
  if (!FaissAvailable()) GTEST_SKIP() << "this build has no FAISS (libfaiss-dev)";
  for (const auto& [descriptor, resolved] :
       {std::pair<std::string, std::string>{"LDB", "ivf"}, {"HOG", "hnsw"}}) {
    SCOPED_TRACE(descriptor);
    const std::string dir = testing::TempDir();
    const std::string config = SampleConfig(dir);
    const auto run = [&](const std::string& engine, const std::string& name) {
      return RunProgram(
          testing::TestOpenableExe(),
          {config, "--set", "Image_descriptor=" + descriptor, "--set", "Approximate_search=1",
           "--set", "Approximate_engine=" + engine, "--set", "Matches_name=out/" + name + ".csv",
           "--set", "Txt_name=", "--set", "Npy_name=", "--set", "Png_name="},
          dir);
    };
    const Outcome automatic = run("auto", "auto"), named = run(resolved, "named");
    ASSERT_EQ(automatic.status, 0) << automatic.err << automatic.out;
    ASSERT_EQ(named.status, 0) << named.err << named.out;
    EXPECT_NE(automatic.out.find("index " + resolved + " (Approximate_engine auto)"),
              std::string::npos)
        << automatic.out;
    EXPECT_NE(named.out.find("index " + resolved + "\n"), std::string::npos) << named.out;
    const std::string kept = ReadAll(dir + "/out/auto.csv");
    // 10 for each of 300 queries, but for the last queries' candidates among the first
    // references: their diagonals hold fewer than L = 10 frames (no value, Sequence_partial
    // ahead), at most 9 such cells per query over the last 9 queries.
    EXPECT_GE(std::count(kept.begin(), kept.end(), '\n'), 3000 - 45);
    EXPECT_EQ(kept, ReadAll(dir + "/out/named.csv"));
  }
}

TEST(TestOpenABLE, SampleRunWritesEveryOutputAndFindsTheSeasonDiagonal) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(), {SampleConfig(dir)}, dir);
  ASSERT_EQ(o.status, 0) << o.err << o.out;
  EXPECT_NE(o.out.find("ms per image"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("ns per pair"), std::string::npos) << o.out;
  EXPECT_NE(o.err.find("describing"), std::string::npos) << "no progress lines: " << o.err;

  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 600);
  ASSERT_EQ(m.cols, 600);
  // Cells without a value (the corners, whose diagonals are shorter than a sequence) are +inf.
  const cv::Mat1b finite = m < std::numeric_limits<float>::infinity();
  double lo, hi;
  cv::minMaxLoc(m, &lo, &hi, nullptr, nullptr, finite);
  EXPECT_GE(lo, 0.0);
  EXPECT_FLOAT_EQ(static_cast<float>(hi), 1.0f);  // Eq. 5
  EXPECT_EQ(cv::countNonZero(finite != finite.t()), 0);
  cv::Mat1f shown = m.clone();
  shown.setTo(-1.0f, ~finite);
  EXPECT_EQ(cv::norm(shown, shown.t(), cv::NORM_INF), 0.0);

  // The text file holds M'' (Threshold is set), consistent with the .npy M'.
  std::istringstream txt(ReadAll(dir + "/out/matrix.txt"));
  int mismatches = 0, rows = 0;
  std::string line;
  while (std::getline(txt, line)) {
    std::istringstream cells(line);
    int v, col = 0;
    while (cells >> v) {
      mismatches += v != (m(rows, col) < 0.3f ? 0 : 1);
      ++col;
    }
    EXPECT_EQ(col, 600);
    ++rows;
  }
  EXPECT_EQ(rows, 600);
  EXPECT_EQ(mismatches, 0);

  const cv::Mat png = cv::imread(dir + "/out/matrix.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.size(), cv::Size(600, 600));
  EXPECT_EQ(png.type(), CV_8UC3);
  // Map 4 is (1-s, 1-s, s): check one pixel against the matrix.
  const cv::Vec3b px = png.at<cv::Vec3b>(310, 20);
  EXPECT_NEAR(px[2], 255.f * m(310, 20), 1.0);
  EXPECT_NEAR(px[0], 255.f * (1 - m(310, 20)), 1.0);
  const cv::Mat thr = cv::imread(dir + "/out/matrix_thresholded.png", cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(thr.size(), cv::Size(600, 600));

  // Winter (rows 300-599) against summer (columns 0-299): the best match of a winter frame
  // should lie within 2 frames of the same place far more often than chance (5/300).
  const double r1 = AlignedRecallAt1(m, 300, 0, 300, 2);
  std::cout << "[ sample ] winter vs summer, LDB L=10: R@1 (+-2) = " << r1 << "\n";
  EXPECT_GT(r1, 0.3) << "chance is " << 5.0 / 300;

  // No temporary file is left in the output folder.
  for (const auto& e : fs::directory_iterator(dir + "/out"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// PNG frames are decoded and the matrix images written without OpenCV's imgcodecs, whose
// GDAL, GDCM and OpenEXR chain (about 120 libraries) cost every run about 80 ms at start-up:
// the dynamic loader's own log (LD_DEBUG=files) must not name it.
TEST(TestOpenABLE, PngRunDoesNotLoadImgcodecs) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(
      "/usr/bin/env", {"LD_DEBUG=files", testing::TestOpenableExe(), SampleConfig(dir)}, dir);
  ASSERT_EQ(o.status, 0) << o.out;
  ASSERT_NE(o.err.find("file=libopencv_core"), std::string::npos)
      << "the loader's log is missing, so the test cannot see what was loaded";
  EXPECT_EQ(o.err.find("libopencv_imgcodecs"), std::string::npos);
  EXPECT_EQ(o.err.find("libgdal"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir + "/out/matrix.png"));
}

TEST(TestOpenABLE, OverridesRangeAndSingleSequence) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(
      testing::TestOpenableExe(),
      {SampleConfig(dir), "--set", "Images_path_2=", "--set", "Final_image=50", "--set",
       "Initial_image=10", "--set", "Image_sequences=1", "--set", "Exclusion=10", "--quiet"},
      dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(o.err, "");  // --quiet: no progress, and no warning
  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 40);
  for (int i = 0; i < 40; ++i) EXPECT_EQ(m(i, i), 0.f);
  EXPECT_NE(o.out.find("40 frames"), std::string::npos) << o.out;
  // The sample's Exclusion (100) leaves none of the 40 frames a candidate: said in one line.
  const Outcome all_excluded =
      RunProgram(testing::TestOpenableExe(),
                 {SampleConfig(dir), "--set", "Images_path_2=", "--set", "Final_image=50", "--set",
                  "Initial_image=10", "--set", "Image_sequences=1", "--quiet"},
                 dir);
  ASSERT_EQ(all_excluded.status, 0) << all_excluded.err;
  EXPECT_TRUE(OneLine(all_excluded.err)) << all_excluded.err;
  EXPECT_NE(all_excluded.err.find("warning: Exclusion: 100 leaves no frame a candidate"),
            std::string::npos)
      << all_excluded.err;
}

// Auto mode with a tiny Memory_limit: the run says it is bounded and why, writes the matches
// and no matrix, and its best matches equal those the dense run writes from its matrix.
TEST(TestOpenABLE, AutoModeSwitchesToBoundedAndAgreesWithDense) {
  const std::string dir = testing::TempDir();
  const std::vector<std::string> common = {
      SampleConfig(dir),  "--set", "Ground_truth_type=", "--set",
      "Evaluation_name=", "--set", "Best_matches=3"};
  std::vector<std::string> bounded = common;
  for (const char* a : {"--set", "Memory_limit=0.0001", "--set", "Matches_name=bounded.csv"})
    bounded.push_back(a);
  const Outcome b = RunProgram(testing::TestOpenableExe(), bounded, dir);
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_NE(b.out.find("mode: bounded (Matrix_mode 0: the 600x600 matrix needs"), std::string::npos)
      << b.out;
  EXPECT_NE(b.err.find("Png_name: not written: the run is bounded"), std::string::npos) << b.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/matrix.npy"));
  std::vector<std::string> dense = common;
  for (const char* a : {"--set", "Matrix_mode=1", "--set", "Matches_name=dense.csv"})
    dense.push_back(a);
  const Outcome d = RunProgram(testing::TestOpenableExe(), dense, dir);
  ASSERT_EQ(d.status, 0) << d.err;
  // Same queries, references and ranks; distances (and the distance scores) differ only by
  // the Eq. 5 divisor (the bounded run computes the cross block only), so compare query,
  // reference and rank.
  auto columns = [](const std::string& csv) {
    std::string out;
    std::istringstream in(csv);
    for (std::string line; std::getline(in, line);) {
      const auto a = line.find(','), b = line.find(',', a + 1), c = line.find(',', b + 1);
      const auto d = line.find(',', c + 1);
      out += line.substr(0, b) + line.substr(c, d - c) + "\n";
      (void)a;
    }
    return out;
  };
  const std::string bc = ReadAll(dir + "/bounded.csv"), dc = ReadAll(dir + "/dense.csv");
  EXPECT_EQ(std::count(bc.begin(), bc.end(), '\n'), 1 + 300 * 3);
  EXPECT_EQ(columns(bc), columns(dc));
}

TEST(TestOpenABLE, BoundedModeNeedsAMatchesFile) {
  const std::string dir = testing::TempDir();
  const Outcome o =
      RunProgram(testing::TestOpenableExe(), {SampleConfig(dir), "--set", "Matrix_mode=2"}, dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("Test_OpenABLE: error: Matches_name: empty, but Matrix_mode 2 (bounded) "
                       "keeps only matches; expected a .npy or .csv path"),
            std::string::npos)
      << o.err;
}

// The records of a matches file as text: one vector of fields per line, the header first.
std::vector<std::vector<std::string>> CsvFields(const std::string& text) {
  std::vector<std::vector<std::string>> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string f; std::getline(cells, f, ',');) fields.push_back(f);
    out.push_back(fields);
  }
  return out;
}

// Without ground truth, Report_name writes the page of the run's answers and Matches_name marks
// the best matches accepted (ratio <= Match_threshold) and confirmed (Match_consistency): both
// checked against a brute-force reading of the run's .npy (e2e_support.h), the matches file
// against AcceptedMatches over its own rank-1 records, in both of its encodings. Progress lines
// name the report and the writing of the outputs.
TEST(TestOpenABLE, WithoutGroundTruthTheReportAndTheMatchesFileShowTheAcceptedMatches) {
  const std::string dir = testing::TempDir();
  const std::string preset = testing::SourceDir() + "/config/presets/across_conditions.txt";
  const auto run = [&](const std::string& matches) {
    return RunProgram(
        testing::TestOpenableExe(),
        {preset, "--set", "Images_path=" + testing::SampleDir() + "/summer", "--set",
         "Images_path_2=" + testing::SampleDir() + "/winter", "--set", "Npy_name=out/m.npy",
         "--set", "Png_name=", "--set", "Report_name=out/report.html", "--set", "Report_examples=3",
         "--set", "Matches_name=out/" + matches},
        dir);
  };
  const Outcome o = run("matches.csv");
  ASSERT_EQ(o.status, 0) << o.err << o.out;
  // Progress lines for the report and for writing the outputs, as for description and matching.
  for (const char* stage : {"  describing ", "  matching ", "  report ", "  writing "})
    EXPECT_NE(o.err.find(stage), std::string::npos) << stage << "\n" << o.err;
  EXPECT_EQ(o.err.find("error"), std::string::npos) << o.err;

  // Brute force over the winter queries (rows 300..599) against the summer references.
  const int n = 300;
  const cv::Mat1f m = ReadNpy(dir + "/out/m.npy");
  ASSERT_EQ(m.rows, 2 * n);
  const std::vector<bool> agree = AgreeingByBruteForce(m, n, n, n, 40);
  std::vector<int> best(n, -1);
  std::vector<float> ratio(n, 1.0f);
  std::vector<int> within(n, 0), confirmed(n, 0);
  for (int q = 0; q < n; ++q) {
    for (int c = 0; c < n; ++c)
      if (std::isfinite(m(n + q, c)) && (best[q] < 0 || m(n + q, c) < m(n + q, best[q])))
        best[q] = c;
    if (best[q] < 0) continue;
    float rival = std::numeric_limits<float>::infinity();
    for (int c = 0; c < n; ++c)
      if (std::abs(c - best[q]) > 10 && std::isfinite(m(n + q, c)))
        rival = std::min(rival, m(n + q, c));
    ratio[q] = std::isfinite(rival) && rival > 0 ? m(n + q, best[q]) / rival : 1.0f;
    within[q] = ratio[q] <= 0.9f;
    confirmed[q] = within[q] && agree[q];
  }
  const int accepted = static_cast<int>(std::count(within.begin(), within.end(), 1));
  const int kept = static_cast<int>(std::count(confirmed.begin(), confirmed.end(), 1));
  ASSERT_GT(kept, 50);
  ASSERT_LT(kept, accepted);  // the confirmation refuses some
  EXPECT_NE(o.out.find("accepted: " + std::to_string(kept) + " of 300 best matches"),
            std::string::npos)
      << o.out;

  // The matches file: rank-1 records carry the verdicts, the others 0.
  const auto csv = CsvFields(ReadAll(dir + "/out/matches.csv"));
  ASSERT_GT(csv.size(), 1u);
  EXPECT_EQ(csv[0], (std::vector<std::string>{"query", "reference", "distance", "rank", "score",
                                              "accepted", "confirmed"}));
  std::vector<Match> records;
  int rank_one = 0;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    const std::vector<std::string>& f = csv[i];
    ASSERT_EQ(f.size(), 7u) << i;
    const Match r{std::stoi(f[0]), std::stoi(f[1]), std::stof(f[2]), std::stoi(f[3]),
                  std::stof(f[4])};
    records.push_back(r);
    const int a = std::stoi(f[5]), c = std::stoi(f[6]);
    if (r.rank != 1) {
      EXPECT_EQ(a + c, 0) << i;
      continue;
    }
    ++rank_one;
    EXPECT_EQ(r.reference, best[r.query]) << r.query;
    EXPECT_EQ(a, within[r.query]) << r.query;
    EXPECT_EQ(c, confirmed[r.query]) << r.query;
  }
  EXPECT_EQ(rank_one, n);
  Config config = LoadConfig(preset);
  const AgreementOptions agreement = AgreementOf(config.matching);
  const std::vector<std::uint8_t> rule = AcceptedMatches(records, n, 0.9, &agreement);
  EXPECT_EQ(std::vector<int>(rule.begin(), rule.end()), confirmed);

  // The same flags in the .npy form: 22-byte records, the verdicts in the last two bytes.
  ASSERT_EQ(run("matches.npy").status, 0);
  const std::string npy = ReadAll(dir + "/out/matches.npy");
  const std::size_t data = npy.size() - 22 * records.size();
  ASSERT_EQ((npy.size() - data) % 22, 0u);
  for (std::size_t i = 0; i < records.size(); ++i) {
    EXPECT_EQ(npy[data + 22 * i + 20], std::stoi(csv[i + 1][5])) << i;
    EXPECT_EQ(npy[data + 22 * i + 21], std::stoi(csv[i + 1][6])) << i;
  }

  // The page: no ground truth said plainly, the operating point, and the three most
  // confident accepted matches with their two frames.
  const std::string page = ReadAll(dir + "/out/report.html");
  EXPECT_NE(page.find("<b>No ground truth.</b>"), std::string::npos);
  for (const char* id : {"settings", "operating-point", "matrix", "explore", "accepted"})
    EXPECT_NE(page.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
  for (const char* id : {"figures", "pr", "wrong-matches", "misses"})
    EXPECT_EQ(page.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
  EXPECT_NE(page.find("; " + std::to_string(accepted) + " accepted with ratio score &lt;= 0.9"),
            std::string::npos);
  EXPECT_NE(page.find(std::to_string(kept) + " of them confirmed by 1 independent query"),
            std::string::npos);
  std::vector<int> order;
  for (int q = 0; q < n; ++q)
    if (confirmed[q]) order.push_back(q);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ratio[a] < ratio[b]; });
  const std::vector<std::string> winter = ListImages(testing::SampleDir() + "/winter", "");
  const std::vector<std::string> summer = ListImages(testing::SampleDir() + "/summer", "");
  const std::size_t table = page.find("data-kind=\"accepted-confident\"");
  ASSERT_NE(table, std::string::npos);
  std::size_t at = table;
  for (int k = 0; k < 3; ++k) {
    const int q = order[k];
    at = page.find("<tr data-query=\"", at + 1);
    ASSERT_NE(at, std::string::npos);
    EXPECT_EQ(std::stoi(page.substr(at + 16)), q) << k;
    const std::string row = page.substr(at, page.find("</tr>", at) - at);
    EXPECT_NE(row.find("alt=\"" + fs::path(winter[q]).filename().string() + "\""),
              std::string::npos)
        << q;
    EXPECT_NE(row.find("alt=\"" + fs::path(summer[best[q]]).filename().string() + "\""),
              std::string::npos)
        << q;
  }
}

// A bounded run keeps no matrix: no report, and a note says so.
TEST(TestOpenABLE, ABoundedRunWritesNoReportAndSaysSo) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {SampleConfig(dir), "--quiet", "--set", "Matrix_mode=2", "--set",
                                "Matches_name=out/k.csv", "--set", "Report_name=out/report.html"},
                               dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_NE(o.err.find("note: Report_name: not written: the run is bounded"), std::string::npos)
      << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out/report.html"));
  EXPECT_TRUE(fs::exists(dir + "/out/k.csv"));
}

// --help fits a screen for every program: at most 55 lines of at most 92 columns, with the
// usage, an example and where the rest is; Test_OpenABLE's names keys people change most,
// each a real key (so its default is shown).
TEST(TestOpenABLE, EveryProgramsHelpFitsAScreen) {
  const std::string dir = testing::TempDir();
  for (const std::string& exe : {testing::TestOpenableExe(), testing::OpenableSweepExe(),
                                 testing::OpenableSnapsExe(), testing::OpenableEvaluateExe()}) {
    const Outcome o = RunProgram(exe, {"--help"}, dir);
    ASSERT_EQ(o.status, 0) << exe << "\n" << o.err;
    EXPECT_EQ(o.err, "") << exe;
    std::istringstream lines(o.out);
    std::string line;
    int count = 0;
    while (std::getline(lines, line)) {
      ++count;
      EXPECT_LE(line.size(), 92u) << exe << ": " << line;
    }
    EXPECT_LE(count, 55) << exe << "\n" << o.out;
    EXPECT_EQ(o.out.rfind("Usage: ", 0), 0u) << exe;
    EXPECT_NE(o.out.find("Example"), std::string::npos) << exe;
    EXPECT_NE(o.out.find("--help-keys"), std::string::npos) << exe;
  }
  const Outcome o = RunProgram(testing::TestOpenableExe(), {"--help"}, dir);
  for (const char* key : {"Images_path_2", "Image_descriptor", "Image_sequences", "Npy_name",
                          "Ground_truth_type", "Report_name"})
    EXPECT_NE(o.out.find(std::string("\n  ") + key + " "), std::string::npos) << key;
  EXPECT_NE(o.out.find("Image_sequences    "), std::string::npos);
}

// The timings block keeps every stage's line when geometric verification runs too (the
// loop-closure preset verifies): description, matching, sequences, verification, export.
TEST(TestOpenABLE, TimingsListEveryStageWithVerification) {
  const std::string dir = testing::TempDir();
  const Outcome o =
      RunProgram(testing::TestOpenableExe(),
                 {testing::SourceDir() + "/config/presets/loop_closure.txt", "--quiet", "--set",
                  "Images_path=" + testing::SampleDir() + "/summer", "--set", "Npy_name=", "--set",
                  "Png_name="},
                 dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const size_t timings = o.out.find("Timings (wall clock):\n");
  ASSERT_NE(timings, std::string::npos) << o.out;
  size_t at = timings;
  for (const char* line : {"\n  total ", "\n  description ", "\n  matching ",
                           "\n  sequences+norm. ", "\n  verification ", "\n  export "}) {
    const size_t next = o.out.find(line, at);
    EXPECT_NE(next, std::string::npos) << line << "\n" << o.out;
    if (next != std::string::npos) at = next;
  }
}

// --help-keys lists every key; --help-keys GROUP the keys of that group exactly, as the
// Markdown reference (docs/configuration.md) groups them; an unknown group is a usage error.
TEST(TestOpenABLE, HelpKeysListsEveryKeyOrOneGroup) {
  const std::string dir = testing::TempDir();
  const Outcome all = RunProgram(testing::TestOpenableExe(), {"--help-keys"}, dir);
  ASSERT_EQ(all.status, 0) << all.err;
  for (const auto& key : ConfigKeyNames())
    EXPECT_NE(all.out.find("\n  " + key + " "), std::string::npos) << key;
  // The keys of each group of the Markdown reference: "### Group" then "| `Key` ...".
  const Outcome md = RunProgram(testing::TestOpenableExe(), {"--help-markdown"}, dir);
  std::map<std::string, std::set<std::string>> groups;
  std::string group, line;
  std::istringstream lines(md.out);
  while (std::getline(lines, line)) {
    if (line.rfind("### ", 0) == 0) group = line.substr(4);
    if (line.rfind("| `", 0) == 0) groups[group].insert(line.substr(3, line.find('`', 3) - 3));
  }
  ASSERT_GE(groups.size(), 8u);
  for (const auto& [name, keys] : groups) {
    const std::string first_word = name.substr(0, name.find(' '));
    const Outcome o = RunProgram(testing::TestOpenableExe(), {"--help-keys", first_word}, dir);
    ASSERT_EQ(o.status, 0) << name << ": " << o.err;
    std::set<std::string> listed;
    std::istringstream out(o.out);
    while (std::getline(out, line))
      if (line.size() > 2 && line[0] == ' ' && line[1] == ' ' && line[2] != ' ')
        listed.insert(line.substr(2, line.find(' ', 2) - 2));
    EXPECT_EQ(listed, keys) << name;
  }
  const Outcome bad = RunProgram(testing::OpenableSweepExe(), {"--help-keys=Colours"}, dir);
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.out, "");
  EXPECT_TRUE(OneLine(bad.err)) << bad.err;
  EXPECT_EQ(bad.err.rfind("openable_sweep: --help-keys: no group \"Colours\"; expected one of "
                          "Datasets, ",
                          0),
            0u)
      << bad.err;
}

TEST(TestOpenABLE, VideoModeReadsFrames) {
  const std::string dir = testing::TempDir();
  const std::string video = dir + "/clip.avi";
  {
    cv::VideoWriter writer = MjpgWriter(video);
    if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV cannot write MJPG video";
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(testing::SampleDir() + "/summer"))
      names.push_back(e.path().string());
    std::sort(names.begin(), names.end());
    for (int i = 0; i < 30; ++i) writer.write(cv::imread(names[i]));
  }
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {SampleConfig(dir), "--set", "Frame_mode=1", "--set",
                                "Video_path_1=" + video, "--set", "Image_sequences=3"},
                               dir);
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(ReadNpy(dir + "/out/matrix.npy").rows, 30);
}

// Every bad input: exit status 1, one line on stderr naming the key or file, and nothing in
// the output folder.
struct BadInput {
  const char* name;
  std::vector<std::string> sets;  // overrides on the sample configuration
  std::string expect;             // text the error line must contain
};

// Named in test listings and CTest by its case name rather than by its bytes.
void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }

class BadInputs : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputs, OneLineNonZeroExitNoOutput) {
  const BadInput& c = GetParam();
  const std::string dir = testing::TempDir();
  // Material for the cases: an empty folder, a folder with a corrupt image, a folder with
  // images of two sizes, a text file posing as a video.
  fs::create_directories(dir + "/empty");
  fs::create_directories(dir + "/corrupt");
  fs::copy(testing::SampleDir() + "/summer/images-00010.png", dir + "/corrupt/a1.png");
  std::ofstream(dir + "/corrupt/a2.png") << "not a png at all";
  fs::create_directories(dir + "/sizes");
  cv::imwrite(dir + "/sizes/f1.png", cv::Mat(32, 64, CV_8UC1, cv::Scalar(9)));
  cv::imwrite(dir + "/sizes/f2.png", cv::Mat(40, 64, CV_8UC1, cv::Scalar(9)));
  std::ofstream(dir + "/fake.avi") << "text";
  std::ofstream(dir + "/fake.txt") << "text that FFmpeg would render as frames\n";
  // Two traversals of 20 and 30 frames, which an aligned ground truth cannot pair frame by frame.
  fs::create_directories(dir + "/twenty");
  fs::create_directories(dir + "/thirty");
  for (int i = 0; i < 30; ++i) {
    const cv::Mat frame(32, 64, CV_8UC1, cv::Scalar(4 * i));
    cv::imwrite(dir + "/thirty/f" + std::to_string(i) + ".png", frame);
    if (i < 20) cv::imwrite(dir + "/twenty/f" + std::to_string(i) + ".png", frame);
  }

  std::vector<std::string> args = {SampleConfig(dir)};
  for (auto s : c.sets) {
    for (std::string from : {std::string("$DIR")}) {
      const auto pos = s.find(from);
      if (pos != std::string::npos) s.replace(pos, from.size(), dir);
    }
    args.push_back("--set");
    args.push_back(s);
  }
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << "stderr: " << o.err;
  EXPECT_NE(o.err.find(c.expect), std::string::npos) << "stderr: " << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out")) << "outputs left behind";
}

INSTANTIATE_TEST_SUITE_P(
    Errors, BadInputs,
    ::testing::Values(
        BadInput{"MissingFolder", {"Images_path=$DIR/nope"}, "Images_path: folder \""},
        BadInput{"EmptyFolder", {"Images_path=$DIR/empty"}, "Images_path: "},
        // Two frames each: sequences of one frame, so that the frames are read at all.
        BadInput{"CorruptImage", {"Images_path=$DIR/corrupt", "Image_sequences=1"}, "a2.png"},
        BadInput{"DifferentSizes",
                 {"Images_path=$DIR/sizes", "Images_path_2=", "Image_sequences=1"},
                 "f2.png"},
        BadInput{"MatrixImageNotPng",
                 {"Png_name=out/m.jpg"},
                 "Png_name: \"out/m.jpg\" does not end in .png; expected a .png path"},
        BadInput{
            "AlignedTruthOfUnequalTraversals",
            {"Images_path=$DIR/twenty", "Images_path_2=$DIR/thirty", "Ground_truth_type=aligned"},
            "Ground_truth_type: aligned pairs query frame i with reference frame i, but "
            "the query traversal has 30 frames and the reference traversal 20"},
        BadInput{"UnopenableVideo", {"Frame_mode=1", "Video_path_1=$DIR/fake.avi"}, "fake.avi"},
        BadInput{"TextAsVideo", {"Frame_mode=1", "Video_path_1=$DIR/fake.txt"}, "fake.txt"},
        BadInput{"Surf", {"Image_descriptor=SURF"}, "SURF"},
        BadInput{"UnknownDescriptor", {"Image_descriptor=XYZ"}, "Image_descriptor"},
        BadInput{"StereoWithSecondTraversal", {"Camera_type=1"}, "Images_path_2: "},
        BadInput{"StereoVideo",
                 {"Camera_type=1", "Frame_mode=1", "Video_path_1=$DIR/a.avi"},
                 "Frame_mode: 1 with Camera_type 1"},
        BadInput{"StereoWithoutCalibration",
                 {"Camera_type=1", "Images_path_2=", "Images_path_left=$DIR/l",
                  "Images_path_right=$DIR/r"},
                 "Calibration_path: empty"},
        BadInput{"DldbWithoutStereo",
                 {"Image_descriptor=D-LDB"},
                 "Image_descriptor: D-LDB needs Camera_type 1 (stereo)"},
        BadInput{"OutOfRange", {"Matrix_color=12"}, "Matrix_color"},
        BadInput{"UnknownKey", {"Patch_sise=3"}, "did you mean \"Patch_size\""},
        BadInput{"RangeOutside", {"Initial_image=400", "Final_image=500"}, "Initial_image"},
        // The sample's frames are grey stored as RGB: Eq. 6 would give constant images.
        BadInput{"IlluminationOnGreyFrames", {"Illumination_invariance=1"}, "is grey"},
        BadInput{"OneLambdaOnly", {"Lambda_red=610"}, "Lambda_red"},
        BadInput{"LambdasOutOfOrder",
                 {"Lambda_red=470", "Lambda_green=535", "Lambda_blue=610"},
                 "Lambda_blue"},
        BadInput{"PanoramasWiderThanTheFrame",
                 {"Camera_type=2", "Panoramas=40", "Description_type=1", "Grid_x=2"},
                 "Grid_x x Panoramas"},
        BadInput{"CrossCorrelationNeedsTheDenseMatrix",
                 {"Camera_type=2", "Matrix_mode=2", "Matches_name=out/m.csv"},
                 "Panorama_matching: 1"},
        BadInput{"UnknownScore", {"Match_score=confidence"}, "Match_score"},
        BadInput{"UnknownNameInAFusion",
                 {"Image_descriptor=HOG+XYZ"},
                 "Image_descriptor: unknown descriptor \"XYZ\""},
        BadInput{"EmptyNameInAFusion",
                 {"Image_descriptor=HOG++LDB"},
                 "Image_descriptor: \"HOG++LDB\" has an empty name"},
        BadInput{"DescriptorTwiceInAFusion", {"Image_descriptor=HOG,hog"}, "names HOG twice"},
        BadInput{"RatioWindowAsLargeAsTheReferences",
                 {"Match_score=ratio", "Match_score_window=300"},
                 "Match_score_window: 300"},
        BadInput{"FusionOfDistancesWithoutWeights",
                 {"Image_descriptor=HOG+LDB"},
                 "Fusion_weights: empty, but Image_descriptor \"HOG+LDB\" fuses distances of "
                 "different kinds (HOG: L2, LDB: Hamming)"},
        BadInput{"WeightsForAnotherNumberOfDescriptors",
                 {"Image_descriptor=HOG+LDB", "Fusion_weights=1,1,1"},
                 "Fusion_weights: \"1,1,1\""},
        BadInput{"NegativeWeight",
                 {"Image_descriptor=HOG+LDB", "Fusion_weights=1,-1"},
                 "Fusion_weights"},
        BadInput{"FusionNeedsTheDenseMatrix",
                 {"Image_descriptor=HOG+LDB", "Fusion_weights=1,1", "Matrix_mode=2",
                  "Matches_name=out/m.csv"},
                 "Image_descriptor: \"HOG+LDB\" fuses descriptors, which needs the dense"},
        BadInput{"ContrastNeedsTheDenseMatrix",
                 {"Contrast_enhancement=1", "Matrix_mode=2", "Matches_name=out/m.csv"},
                 "Contrast_enhancement: 1 needs the dense matrix"},
        BadInput{"SadHasNoApproximateSearch",
                 {"Image_descriptor=SAD", "Approximate_search=1", "Matches_name=out/m.csv"},
                 "Approximate_search: 1 with Image_descriptor SAD"},
        BadInput{"SadPatchTooLarge",
                 {"Image_descriptor=SAD", "Patch_size=32", "Sad_patch=20"},
                 "Sad_patch: 20"},
        BadInput{"UnknownPartial", {"Sequence_partial=drop"}, "Sequence_partial"},
        // Sequences longer than the traversals leave no cell with a value (Sequence_partial
        // ahead or skip): refused before any frame is read.
        BadInput{"SequencesLongerThanBothTraversals",
                 {"Final_image=39", "Image_sequences=100"},
                 "Image_sequences: 100 frames, but the traversals have 39 (Images_path) and 39 "
                 "(Images_path_2) frames: with Sequence_partial ahead a cell has a value only on "
                 "a diagonal of at least 100 frames"},
        BadInput{"SequencesLongerThanTheShorterTraversal",
                 {"Images_path=$DIR/twenty", "Images_path_2=$DIR/thirty", "Image_sequences=25",
                  "Sequence_partial=skip"},
                 "expected Image_sequences <= 20, or Sequence_partial scale"},
        BadInput{"SequencesLongerThanTheOnlyTraversal",
                 {"Images_path=$DIR/twenty", "Images_path_2=", "Image_sequences=21"},
                 "the matrix would hold no value; expected Image_sequences <= 20"}),
    [](const ::testing::TestParamInfo<BadInput>& info) { return std::string(info.param.name); });

// Sequences longer than the traversals: with Sequence_partial scale every cell still has a
// value (the partial sums scaled up), so the run goes on.
TEST(TestOpenABLE, LongSequencesWithScaledPartialSumsRun) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {SampleConfig(dir), "--quiet", "--set", "Final_image=39", "--set",
                                "Image_sequences=100", "--set", "Sequence_partial=scale"},
                               dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 78);
  EXPECT_EQ(cv::countNonZero(m <= 1.0f), 78 * 78);  // every cell finite
}

// One traversal whose frames have no candidate with a value (candidates Exclusion frames back,
// sequences longer than what remains): the matrix is written, and the run says in one line,
// on stderr and in the report, why no loop can be found. Checked here on the matrix itself.
TEST(TestOpenABLE, NoCandidateWithAValueIsSaidInOneLine) {
  const std::string dir = testing::TempDir();
  const Outcome o = RunProgram(testing::TestOpenableExe(),
                               {SampleConfig(dir), "--quiet", "--set", "Images_path_2=", "--set",
                                "Image_sequences=250", "--set", "Exclusion=100"},
                               dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string line =
      "warning: Image_sequences: 250 leaves no candidate with a value (a frame's candidates are "
      "at least Exclusion 100 frames back";
  EXPECT_NE(o.err.find("Test_OpenABLE: " + line), std::string::npos) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.out.find("  " + line), std::string::npos) << o.out;
  // Every candidate cell (q, j <= q - 100) of the 300 x 300 matrix is +inf, and some other
  // cell has a value.
  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 300);
  int finite_candidates = 0;
  for (int q = 100; q < 300; ++q)
    for (int j = 0; j <= q - 100; ++j) finite_candidates += std::isfinite(m(q, j)) ? 1 : 0;
  EXPECT_EQ(finite_candidates, 0);
  EXPECT_GT(cv::countNonZero(m <= 1.0f), 0);
  // With sequences that fit, no such line.
  const Outcome fit = RunProgram(testing::TestOpenableExe(),
                                 {SampleConfig(dir), "--quiet", "--set", "Images_path_2=", "--set",
                                  "Image_sequences=150", "--set", "Exclusion=100"},
                                 dir);
  ASSERT_EQ(fit.status, 0) << fit.err;
  EXPECT_EQ(fit.err.find("warning"), std::string::npos) << fit.err;
}

TEST(TestOpenABLE, MissingOrBrokenConfigFile) {
  const std::string dir = testing::TempDir();
  Outcome o = RunProgram(testing::TestOpenableExe(), {dir + "/nope.txt"}, dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  EXPECT_NE(o.err.find("nope.txt"), std::string::npos) << o.err;
  std::ofstream(dir + "/bad.txt") << "Frame_mode: 0\nthis is not a key value line\n";
  o = RunProgram(testing::TestOpenableExe(), {dir + "/bad.txt"}, dir);
  EXPECT_EQ(o.status, 1);
  EXPECT_NE(o.err.find("bad.txt:2"), std::string::npos) << o.err;
  o = RunProgram(testing::TestOpenableExe(), {}, dir);
  EXPECT_EQ(o.status, 2);
  o = RunProgram(testing::TestOpenableExe(), {"--bogus"}, dir);
  EXPECT_EQ(o.status, 2);
}

// The bar of the issue, on the shared data: Nordland winter against summer, 1788 + 1788
// frames, LDB, global 64x64, L = 10. The original reached R@1 (+-2 frames) = 0.355.
TEST(TestOpenABLE, NordlandWinterVsSummerBeatsTheOriginal) {
  const std::string data = testing::DatasetsDir() + "/nordland_trimmed";
  OPENABLE_REQUIRE_PATH(data);
  const std::string dir = testing::TempDir();
  const Outcome o =
      RunProgram(testing::TestOpenableExe(),
                 {SampleConfig(dir), "--set", "Images_path=" + data + "/summer", "--set",
                  "Images_path_2=" + data + "/winter", "--set", "Txt_name=", "--set",
                  "Png_name=", "--set", "Threshold=-1", "--quiet"},
                 dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const cv::Mat1f m = ReadNpy(dir + "/out/matrix.npy");
  ASSERT_EQ(m.rows, 3576);
  const double r1 = AlignedRecallAt1(m, 1788, 0, 1788, 2);
  std::cout << "[ nordland ] winter vs summer, LDB global 64x64, L=10: R@1 (+-2) = " << r1 << "\n"
            << o.out;
  EXPECT_GE(r1, 0.355);
}

// Reverse traversal with a monocular camera and the matrix image:
// 300 Nordland summer frames, then the same stretch in winter played backwards as the second
// traversal. Summing sequences along anti-diagonals (Sequence_direction 1) finds query i at
// reference 299 - i; the forward sums do not. In the image of the matrix (Matrix_color 0:
// grey = normalised distance), the revisit is a dark left-side diagonal of the lower-left
// block, as in the ABLE-P figures.
TEST(TestOpenABLE, ReverseTraversalIsFoundAlongTheAntiDiagonal) {
  const std::string data = testing::DatasetsDir() + "/nordland_trimmed";
  OPENABLE_REQUIRE_PATH(data);
  const std::string dir = testing::TempDir();
  const int n = 300;
  std::vector<std::string> winter;
  for (const auto& e : fs::directory_iterator(data + "/winter"))
    winter.push_back(e.path().string());
  std::sort(winter.begin(), winter.end());
  fs::create_directories(dir + "/backwards");
  char name[32];
  for (int i = 0; i < n; ++i) {  // frame i of the folder is winter frame n - 1 - i
    std::snprintf(name, sizeof name, "/f%04d.png", i);
    fs::create_symlink(winter[static_cast<size_t>(n - 1 - i)], dir + "/backwards" + name);
  }
  auto run = [&](int direction) {
    const Outcome o = RunProgram(
        testing::TestOpenableExe(),
        {SampleConfig(dir), "--set", "Images_path=" + data + "/summer", "--set",
         "Final_image=" + std::to_string(n), "--set", "Images_path_2=" + dir + "/backwards",
         "--set", "Txt_name=", "--set", "Threshold=-1", "--set", "Matrix_color=0", "--set",
         "Sequence_direction=" + std::to_string(direction), "--quiet"},
        dir);
    EXPECT_EQ(o.status, 0) << o.err;
    return ReadNpy(dir + "/out/matrix.npy");
  };
  // Share of queries whose best reference is within +-2 frames of the place they show.
  auto recall = [&](const cv::Mat1f& m) {
    int found = 0;
    for (int q = 0; q < n; ++q) {
      cv::Point best;
      cv::minMaxLoc(m.row(n + q).colRange(0, n), nullptr, nullptr, &best);
      found += std::abs(best.x - (n - 1 - q)) <= 2;
    }
    return static_cast<double>(found) / n;
  };
  const cv::Mat1f forward = run(0);
  ASSERT_EQ(forward.rows, 2 * n);
  const double r_forward = recall(forward);
  const cv::Mat1f reverse = run(1);
  ASSERT_EQ(reverse.rows, 2 * n);
  const double r_reverse = recall(reverse);
  std::cout << "[ reverse ] Nordland, 300 frames, winter backwards, L=10: R@1 (+-2) forward "
            << r_forward << ", reverse " << r_reverse << "\n";
  EXPECT_GE(r_reverse, 0.5);
  EXPECT_GE(r_reverse, r_forward + 0.3);

  // The image: pixel (row, column) = cell (row, column), grey = 255 x distance. The mean along
  // the anti-diagonal (left-side diagonal) of the lower-left block is darker than the block and
  // than its main-direction diagonal (row n + q, column q). Winter against summer stays far
  // from 0: measured 121 against 154 and 152.
  const cv::Mat png = cv::imread(dir + "/out/matrix.png", cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(png.rows, 2 * n);
  ASSERT_EQ(png.cols, 2 * n);
  double anti = 0, diagonal = 0;
  for (int q = 0; q < n; ++q) {
    anti += png.at<std::uint8_t>(n + q, n - 1 - q);
    diagonal += png.at<std::uint8_t>(n + q, q);
  }
  anti /= n;
  diagonal /= n;
  const double block = cv::mean(png(cv::Rect(0, n, n, n)))[0];
  EXPECT_LT(anti, 0.85 * block) << "anti-diagonal " << anti << ", block " << block;
  EXPECT_LT(anti, 0.85 * diagonal) << "anti-diagonal " << anti << ", diagonal " << diagonal;
  // And the pixels follow the matrix written beside them.
  EXPECT_NEAR(png.at<std::uint8_t>(n + 10, 17), 255.0 * reverse(n + 10, 17), 1.0);
}

}  // namespace
}  // namespace openable

// --- Interrupted runs, write errors, the descriptor cache ---------------------------------
namespace openable {
namespace {

using namespace e2e;  // NOLINT

std::vector<std::string> FilesUnder(const std::string& dir) {
  std::vector<std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path().string());
  return files;
}

// A run with Descriptor_cache gives the same .npy bytes as one without, cold, warm and after
// the cache lost its last records and got a damaged tail (a run killed while appending).
TEST(TestOpenABLE, DescriptorCacheResumeIsBitIdentical) {
  const std::string dir = testing::TempDir();
  const std::string config = SampleConfig(dir);
  Outcome o = RunProgram(testing::TestOpenableExe(), {config}, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  const std::string clean = ReadAll(dir + "/out/matrix.npy");
  const std::vector<std::string> cache = {"--set", "Descriptor_cache=cache"};
  auto run = [&](const std::string& expect_cache_line) {
    std::vector<std::string> args = {config};
    args.insert(args.end(), cache.begin(), cache.end());
    fs::remove(dir + "/out/matrix.npy");
    const Outcome r = RunProgram(testing::TestOpenableExe(), args, dir);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find(expect_cache_line), std::string::npos) << r.out;
    EXPECT_TRUE(ReadAll(dir + "/out/matrix.npy") == clean) << "matrix differs from a clean run";
    return r;
  };
  // The sample holds frames whose files are byte-identical (dark frames): one record serves
  // them all, so even a cold run has hits.
  run(" of 600 frames from the cache, ");
  run("descriptor cache: 600 of 600 frames from the cache, 0 added");
  const std::vector<std::string> files = FilesUnder(dir + "/cache");
  ASSERT_EQ(files.size(), 1u);
  const std::string bytes = ReadAll(files[0]);
  // Header: 32 bytes, the settings text's length (u32), the text, a u64 checksum. LDB 256
  // bits: 32-byte rows, 64-byte records. Keep 400 records, then half a record and garbage.
  std::uint32_t text = 0;
  std::memcpy(&text, bytes.data() + 32, 4);
  const size_t header = 44 + text, record = 64;
  ASSERT_EQ((bytes.size() - header) % record, 0u);
  ASSERT_GT(bytes.size(), header + 500 * record);
  testing::WriteBytes(files[0], bytes.substr(0, header + 400 * record + 20) + "garbage");
  const Outcome r = run(" of 600 frames from the cache, ");
  EXPECT_NE(r.err.find("Test_OpenABLE: warning: Descriptor_cache: "), std::string::npos) << r.err;
  EXPECT_EQ(ReadAll(files[0]).size(), bytes.size());
}

// SIGTERM while describing Nordland (3576 frames): exit status 143, one line, no file in the
// output folder (no output, no temporary).
TEST(TestOpenABLE, SigtermDuringARunLeavesNoOutput) {
  const std::string data = testing::DatasetsDir() + "/nordland_trimmed";
  OPENABLE_REQUIRE_PATH(data);
  const std::string dir = testing::TempDir();
  const std::string config = SampleConfig(dir);
  const std::string err = dir + "/stderr.log";
  const pid_t child = StartRunToInterrupt(
      dir,
      {testing::TestOpenableExe(), config, "--set", "Images_path=" + data + "/summer", "--set",
       "Images_path_2=" + data + "/winter", "--set", "Threads=1"},
      err);
  ASSERT_GT(child, 0);
  int status = 0;
  if (::waitpid(child, &status, WNOHANG) == child)
    GTEST_SKIP() << "the run finished before it could be interrupted";
  ASSERT_EQ(::kill(child, SIGTERM), 0);
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 143);
  const std::string e = ReadAll(err);
  EXPECT_NE(e.find("Test_OpenABLE: interrupted by SIGTERM (temporary files removed)\n"),
            std::string::npos)
      << e;
  EXPECT_TRUE(FilesUnder(dir + "/out").empty()) << FilesUnder(dir + "/out").front();
}

// Outputs on a full file system: exit 1, one line naming the key, the path and the reason,
// nothing left in the folder (a 64k tmpfs; skipped without the right to mount one).
TEST(TestOpenABLE, FullDiskFailsWithOneLineAndLeavesNothing) {
  const std::string dir = testing::TempDir();
  const std::string out = dir + "/out";
  fs::create_directories(out);
  if (::mount("tmpfs", out.c_str(), "tmpfs", 0, "size=64k") != 0)
    GTEST_SKIP() << "cannot mount a 64k tmpfs (" << std::strerror(errno) << ")";
  const Outcome o = RunProgram(testing::TestOpenableExe(), {SampleConfig(dir)}, dir);
  const std::vector<std::string> left = FilesUnder(out);
  ::umount(out.c_str());
  EXPECT_EQ(o.status, 1) << o.err;
  const size_t error = o.err.find("Test_OpenABLE: error");
  ASSERT_NE(error, std::string::npos) << o.err;
  EXPECT_TRUE(OneLine(o.err.substr(error))) << o.err;
  EXPECT_NE(o.err.find("No space left on device"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("_name: cannot write \"out/matrix."), std::string::npos) << o.err;
  EXPECT_TRUE(left.empty()) << left.front();
}

// Two outputs of one run at one file, or an evaluation prefix that is a folder: refused before
// any work, one line naming both keys, nothing written.
TEST(TestOpenABLE, OutputsAtTheSameFileAreRefusedBeforeWork) {
  const std::string dir = testing::TempDir();
  fs::create_directories(dir + "/evalfolder");
  const std::vector<std::vector<std::string>> cases = {
      {"Txt_name=out/m", "Npy_name=out/m", "Txt_name", "Npy_name"},
      {"Png_name=out/m.png", "Png_threshold_name=out/./m.png", "Png_threshold_name", "Png_name"},
      {"Npy_name=out/e.json", "Evaluation_name=out/e", "Evaluation_name", "Npy_name"},
      {"Evaluation_name=evalfolder", "Png_name=", "Evaluation_name", "is a folder"},
  };
  for (const auto& c : cases) {
    const Outcome o =
        RunProgram(testing::TestOpenableExe(),
                   {testing::SourceDir() + "/config/Config.txt", "--set",
                    "Images_path=" + testing::SampleDir() + "/summer", "--set",
                    "Images_path_2=" + testing::SampleDir() + "/winter", "--set",
                    "Txt_name=", "--set", "Npy_name=", "--set", "Png_name=", "--set",
                    "Evaluation_name=", "--set", "Threshold=0.4", "--set", c[0], "--set", c[1]},
                   dir);
    EXPECT_EQ(o.status, 1) << c[0] << " " << o.err;
    EXPECT_TRUE(OneLine(o.err)) << o.err;
    EXPECT_NE(o.err.find(c[2]), std::string::npos) << o.err;
    EXPECT_NE(o.err.find(c[3]), std::string::npos) << o.err;
    EXPECT_EQ(o.err.find("describing"), std::string::npos) << "work started: " << o.err;
    EXPECT_FALSE(fs::exists(dir + "/out")) << c[0];
    EXPECT_TRUE(fs::is_empty(dir + "/evalfolder"));
  }
}

// Messages that name the real culprit: the real limit of an integer, the working directory a
// relative path was taken from, a descriptor row too large to hold (refused before any work).
TEST(TestOpenABLE, MessagesNameTheRealLimitAndTheWorkingDirectory) {
  const std::string dir = testing::TempDir();
  const BadArgs cases[] = {
      {{"--set", "Initial_image=4294967296"}, {"Initial_image", "2147483647"}},
      {{"--set", "Images_path=no/such/folder"},
       {"no/such/folder", "relative to the working directory", dir}},
      {{"--set", "Image_descriptor=HOG", "--set", "Patch_size=1024", "--set", "Description_type=1",
        "--set", "Grid_x=64", "--set", "Grid_y=32"},
       {"Patch_size", "1024", "Grid_x 64 x Grid_y 32", "GiB per frame"}},
  };
  for (const BadArgs& c : cases) {
    std::vector<std::string> args = {"--set", "Images_path=" + testing::SampleDir() + "/summer",
                                     "--set", "Npy_name=m.npy"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
    EXPECT_EQ(o.status, 1) << o.err;
    EXPECT_TRUE(OneLine(o.err)) << o.err;
    for (const std::string& part : c.parts)
      EXPECT_NE(o.err.find(part), std::string::npos) << part << " in " << o.err;
    EXPECT_EQ(o.err.find("describing"), std::string::npos) << o.err;
    EXPECT_FALSE(fs::exists(dir + "/m.npy"));
  }
}

}  // namespace
}  // namespace openable
