// Frames and folders whose names are not valid UTF-8 (Linux file names are bytes): the programs
// read them, and every text they write (the HTML report, the JSON documents, the CSV files,
// standard output and standard error) is valid UTF-8 and shows such a name by one rule, each
// byte outside a well-formed UTF-8 sequence as \xNN (docs/output_formats.md, "Names that are
// not UTF-8"). Validity is checked by an independent reader (FirstInvalidUtf8Byte,
// tests/test_support.h) and the shown names are written out by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace e2e;  // NOLINT: the e2e helpers are this file's vocabulary

// A frame's real name and the name every output shows.
struct Name {
  std::string file, shown;
};

// The frames of each traversal, the same names in both. The first six are not UTF-8: a Latin-1
// byte, a lone continuation byte, a truncated 3-byte sequence, an overlong '/', a surrogate
// (U+D800) and a code point beyond U+10FFFF; two are valid UTF-8 (kept byte for byte).
const std::vector<Name> kNames = {
    {"caf\xe9 00.png", "caf\\xe9 00.png"},
    {"lone\x80 01.png", "lone\\x80 01.png"},
    {"cut\xe2\x82 02.png", "cut\\xe2\\x82 02.png"},
    {"overlong\xc0\xaf 03.png", "overlong\\xc0\\xaf 03.png"},
    {"surrogate\xed\xa0\x80 04.png", "surrogate\\xed\\xa0\\x80 04.png"},
    {"beyond\xf4\x90\x80\x80 05.png", "beyond\\xf4\\x90\\x80\\x80 05.png"},
    {"valid caf\xc3\xa9 06.png", "valid caf\xc3\xa9 06.png"},
    {"valid \xe2\x82\xac 07.png", "valid \xe2\x82\xac 07.png"},
    {"f08.png", "f08.png"},
    {"f09.png", "f09.png"},
    {"f10.png", "f10.png"},
    {"f11.png", "f11.png"},
};

// The folder of the query traversal, a Latin-1 name, and how it is shown.
const char kQueryFolder[] = "hiver\xe9";
const char kQueryFolderShown[] = "hiver\\xe9";

// `text` as a JSON string literal holds it (the names above hold no quote or control byte).
std::string JsonText(const std::string& text) {
  std::string out;
  for (const char c : text) out += c == '\\' ? std::string("\\\\") : std::string(1, c);
  return out;
}

cv::Mat1b Noise(int seed) {
  cv::Mat1b m(32, 64);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

void WritePng(const std::string& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(cv::imencode(".png", image, bytes));
  testing::WriteBytes(path, std::string(bytes.begin(), bytes.end()));
}

// <dir>/summer and <dir>/<kQueryFolder>, frames of 64 x 32 named kNames. Query frames 6-11 are
// the reference frames with a little noise (found); 0-5 are other images (wrong answers and
// misses), so the report's worst cases show the names that are not UTF-8.
void WriteTraversals(const std::string& dir) {
  fs::create_directories(dir + "/summer");
  fs::create_directories(dir + "/" + kQueryFolder);
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    const cv::Mat1b reference = Noise(static_cast<int>(i) + 1);
    WritePng(dir + "/summer/" + kNames[i].file, reference);
    cv::Mat1b query;
    if (i < 6) {
      query = Noise(static_cast<int>(i) + 100);
    } else {
      cv::Mat1b noise(reference.size());
      cv::randu(noise, 0, 12);
      query = reference + noise;
    }
    WritePng(dir + "/" + kQueryFolder + "/" + kNames[i].file, query);
  }
}

std::vector<std::string> RunSettings(const std::string& dir) {
  return {"Images_path=" + dir + "/summer",
          "Images_path_2=" + dir + "/" + kQueryFolder,
          "Image_descriptor=LDB",
          "Image_sequences=1",
          "Ground_truth_type=aligned",
          "Tolerance=0",
          "Npy_name=out/m.npy",
          "Txt_name=out/m.txt",
          "Matches_name=out/matches.csv",
          "Evaluation_name=out/eval",
          "Report_name=out/report.html",
          "Threads=2"};
}

// Fails the test when `text` (what `what` names) is not valid UTF-8, showing where.
void ExpectValidUtf8(const std::string& text, const std::string& what) {
  const std::size_t bad = testing::FirstInvalidUtf8Byte(text);
  EXPECT_EQ(bad, std::string::npos)
      << what << " is not valid UTF-8 at byte " << bad << ": ..."
      << text.substr(bad == std::string::npos ? 0 : (bad < 40 ? 0 : bad - 40), 80) << "...";
}

// Every file of `folder` that is text (all but .npy and .png).
std::vector<std::string> TextFiles(const std::string& folder) {
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".npy" && ext != ".png") out.push_back(entry.path().string());
  }
  return out;
}

// A run with a report, the evaluation, CSV files and the matrix's settings: every text output
// is valid UTF-8; the report names the frames and the query folder by the rule.
TEST(NonUtf8Names, EveryOutputOfARunIsValidUtf8AndShowsTheNamesByTheRule) {
  const std::string dir = testing::TempDir();
  WriteTraversals(dir);
  const Outcome o = RunTestOpenable(dir, RunSettings(dir));
  ASSERT_EQ(o.status, 0) << o.err;
  ExpectValidUtf8(o.out, "standard output");
  ExpectValidUtf8(o.err, "standard error");
  // The report on standard output names the query folder.
  EXPECT_NE(o.out.find("frames of 64x32 from \"" + dir + "/" + kQueryFolderShown + "\""),
            std::string::npos)
      << o.out;

  const std::vector<std::string> files = TextFiles(dir + "/out");
  EXPECT_EQ(files.size(), 8u);  // report, eval.json, 2 CSV curves, matches, m.txt, 2 settings
  for (const std::string& path : files) ExpectValidUtf8(testing::ReadBytes(path), path);

  const std::string html = testing::ReadBytes(dir + "/out/report.html");
  ASSERT_FALSE(html.empty());
  // The settings table: the query folder (Images_path_2, a quoted value), HTML text.
  EXPECT_NE(html.find("<code>&quot;" + dir + "/" + kQueryFolderShown + "&quot;</code>"),
            std::string::npos);
  // The explorer's data (JSON in the page) lists the frames of each traversal by the rule.
  int lists = 0;
  for (std::size_t at = html.find("\"names\":["); at != std::string::npos;
       at = html.find("\"names\":[", at + 1), ++lists) {
    const std::string list = html.substr(at, html.find(']', at) - at);
    EXPECT_EQ(std::count(list.begin(), list.end(), ','), 11) << list;
    for (const Name& n : kNames)
      EXPECT_NE(list.find("\"" + JsonText(n.shown) + "\""), std::string::npos) << n.shown;
  }
  EXPECT_EQ(lists, 2);  // references and queries
  // The worst cases name their frames (HTML text) by the rule, among them frames whose names
  // are not UTF-8.
  std::set<std::string> shown;
  for (const Name& n : kNames) shown.insert(n.shown);
  // (Searched by hand: std::regex recurses per character, and the page holds long data URIs.)
  int cells = 0, escaped = 0;
  for (std::size_t at = html.find("<br>"); at != std::string::npos;
       at = html.find("<br>", at + 1)) {
    if (html.compare(at, 10, "<br>query ") != 0 && html.compare(at, 14, "<br>reference ") != 0)
      continue;
    const std::size_t begin = html.rfind('>', at - 1) + 1;
    const std::string name = html.substr(begin, at - begin);
    ++cells;
    escaped += name.find("\\x") != std::string::npos;
    EXPECT_TRUE(shown.count(name)) << "a frame named \"" << name << "\"";
  }
  EXPECT_GT(cells, 0);
  EXPECT_GT(escaped, 0);

  // The matrix's settings name the query folder (the second traversal) by the rule.
  const Json settings = ReadJson(dir + "/out/m.npy.json");
  ASSERT_EQ(settings.at("traversals").size(), 2u) << settings.dump();
  EXPECT_EQ(settings.at("traversals").at(1).at("path"), dir + "/" + kQueryFolderShown);
  // The files were read by their real names: 12 + 12 frames.
  EXPECT_EQ(ReadNpy(dir + "/out/m.npy").rows, 24);
}

// The final report as JSON (--json) shows the query folder by the same rule.
TEST(NonUtf8Names, JsonReportShowsTheFolderByTheRule) {
  const std::string dir = testing::TempDir();
  WriteTraversals(dir);
  std::vector<std::string> args = QuietArgs(RunSettings(dir));
  args.push_back("--json");
  const Outcome o = RunProgram(testing::TestOpenableExe(), args, dir);
  ASSERT_EQ(o.status, 0) << o.err;
  ExpectValidUtf8(o.out, "the JSON report");
  const Json report = Json::parse(o.out);
  ASSERT_EQ(report.at("traversals").size(), 2u) << o.out;
  EXPECT_EQ(report.at("traversals").at(1).at("path"), dir + "/" + kQueryFolderShown) << o.out;
}

// A damaged frame whose name is not UTF-8: the one error line names it by the rule; with
// Skip_unreadable the report lists it, skipped, by the same rule.
TEST(NonUtf8Names, ErrorAndSkippedLinesShowTheNameByTheRule) {
  const std::string dir = testing::TempDir();
  WriteTraversals(dir);
  // In both folders: the traversals keep one count of frames when it is skipped.
  testing::WriteBytes(dir + "/summer/broken\xe9\xff 99.png", "not a png");
  testing::WriteBytes(dir + "/" + kQueryFolder + "/broken\xe9\xff 99.png", "not a png");
  const std::string shown = "summer/broken\\xe9\\xff 99.png\"";
  Outcome o = RunTestOpenable(dir, RunSettings(dir));
  EXPECT_EQ(o.status, 1) << o.err;
  EXPECT_TRUE(OneLine(o.err)) << o.err;
  ExpectValidUtf8(o.err, "the error line");
  EXPECT_NE(o.err.find(shown), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir + "/out/report.html"));

  // Without the report: it reads the frames again by their index among all the files.
  std::vector<std::string> settings = RunSettings(dir);
  settings.erase(std::find(settings.begin(), settings.end(), "Report_name=out/report.html"));
  settings.push_back("Skip_unreadable=1");
  o = RunTestOpenable(dir, settings);
  ASSERT_EQ(o.status, 0) << o.err;
  ExpectValidUtf8(o.out, "standard output");
  ExpectValidUtf8(o.err, "standard error");
  EXPECT_NE(o.out.find("    skipped: "), std::string::npos) << o.out;
  EXPECT_NE(o.out.find(shown), std::string::npos) << o.out;
}

// openable_sweep varying the query folder: its CSV (values and labels), JSON and table show
// the folder by the rule.
TEST(NonUtf8Names, SweepCsvJsonAndTableShowTheFolderByTheRule) {
  const std::string dir = testing::TempDir();
  WriteTraversals(dir);
  fs::copy(dir + "/" + kQueryFolder, dir + "/winter");
  const Outcome o = RunProgram(
      testing::OpenableSweepExe(),
      {"--quiet", "--set", "Images_path=" + dir + "/summer", "--set", "Image_descriptor=LDB",
       "--set", "Image_sequences=1", "--set", "Ground_truth_type=aligned", "--set", "Tolerance=0",
       "--vary", "Images_path_2=" + dir + "/winter," + dir + "/" + kQueryFolder, "--output",
       "out/sweep"},
      dir);
  ASSERT_EQ(o.status, 0) << o.err;
  ExpectValidUtf8(o.out, "standard output");
  ExpectValidUtf8(o.err, "standard error");
  const std::string csv = testing::ReadBytes(dir + "/out/sweep.csv");
  const std::string json = testing::ReadBytes(dir + "/out/sweep.json");
  ASSERT_FALSE(csv.empty());
  ExpectValidUtf8(csv, "sweep.csv");
  ExpectValidUtf8(json, "sweep.json");
  EXPECT_NE(csv.find("," + dir + "/" + kQueryFolderShown + ","), std::string::npos) << csv;
  // The sweep's varied values and its run's settings name the folder by the rule.
  const Json sweep = Json::parse(json);
  const std::string shown = dir + "/" + kQueryFolderShown;
  const Json& values = sweep.at("varied").at(0).at("values");
  EXPECT_NE(std::find(values.begin(), values.end(), shown), values.end()) << json;
  const Json& runs = sweep.at("runs");
  EXPECT_TRUE(std::any_of(runs.begin(), runs.end(), [&](const Json& run) {
    return run.at("settings").at("Images_path_2") == shown;
  })) << json;
}

}  // namespace
}  // namespace openable
