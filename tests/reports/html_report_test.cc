#include "OpenABLE/reports/html_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "OpenABLE/io/image_codec.h"
#include "OpenABLE/io/json.h"
#include "OpenABLE/reports/html_explorer.h"
#include "config/config.h"
#include "tests/test_support.h"

namespace openable {
namespace {

constexpr int kFrames = 40;  // per traversal
constexpr int kTolerance = 1;

// Two traversals of kFrames frames, frame-aligned ground truth, random distances with the true
// place made small for most queries: some answers right, some wrong.
struct Fixture {
  Config config;
  cv::Mat1f matrix;
  Evaluation evaluation;

  Fixture() {
    ApplyOverride(config, "Ground_truth_type=aligned");
    ApplyOverride(config, "Tolerance=" + std::to_string(kTolerance));
    evaluation.settings = EvaluationSettingsFrom(config);
    matrix.create(2 * kFrames, 2 * kFrames);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.5f, 1.0f);
    for (int r = 0; r < matrix.rows; ++r)
      for (int c = 0; c < matrix.cols; ++c) matrix(r, c) = u(rng);
    // The true place wins clearly (q % 3 == 1), narrowly (q % 3 == 2), or not at all.
    for (int q = 0; q < kFrames; ++q)
      if (q % 3 != 0) matrix(kFrames + q, q) = q % 3 == 1 ? 0.05f + 0.001f * q : 0.3f + 0.001f * q;
    EvaluateMatrix(evaluation, matrix, EvaluationLayout::TwoTraversals(kFrames, kFrames),
                   "LDB <b>&", "test");
  }
};

struct Expected {
  int query, answer;
  float distance;
  bool correct;
};

// Each query's best match by brute force over the reference columns (ties: lower column).
std::vector<Expected> BruteForce(const cv::Mat1f& m) {
  std::vector<Expected> out;
  for (int q = 0; q < kFrames; ++q) {
    int best = 0;
    for (int c = 1; c < kFrames; ++c)
      if (m(kFrames + q, c) < m(kFrames + q, best)) best = c;
    out.push_back({q, best, m(kFrames + q, best), std::abs(best - q) <= kTolerance});
  }
  return out;
}

TEST(HtmlReport, ConfidentWrongMatchesAreTheWrongAnswersByIncreasingDistance) {
  const Fixture f;
  std::vector<Expected> wrong;
  for (const Expected& e : BruteForce(f.matrix))
    if (!e.correct) wrong.push_back(e);
  std::stable_sort(wrong.begin(), wrong.end(),
                   [](const Expected& a, const Expected& b) { return a.distance < b.distance; });
  ASSERT_GE(wrong.size(), 6u);
  const std::vector<ReportCase> cases = ConfidentWrongMatches(
      f.evaluation.runs[0], f.evaluation.truths[0], f.matrix, 100, 5);
  ASSERT_EQ(cases.size(), 5u);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(cases[k].query, wrong[k].query) << k;
    EXPECT_EQ(cases[k].answer, wrong[k].answer) << k;
    EXPECT_FLOAT_EQ(cases[k].score, wrong[k].distance) << k;
    EXPECT_FALSE(cases[k].correct);
    EXPECT_EQ(cases[k].true_place, wrong[k].query);  // aligned: query i is reference i
  }
  EXPECT_TRUE(ConfidentWrongMatches(f.evaluation.runs[0], f.evaluation.truths[0], f.matrix, 100,
                                    0)
                  .empty());
}

TEST(HtmlReport, MissesAreThePositiveQueriesNotFoundAtTheThreshold) {
  const Fixture f;
  const double threshold = 0.2;
  std::vector<Expected> missed;
  for (const Expected& e : BruteForce(f.matrix))
    if (!(e.correct && e.distance <= threshold)) missed.push_back(e);
  std::stable_sort(missed.begin(), missed.end(),
                   [](const Expected& a, const Expected& b) { return a.distance > b.distance; });
  const std::vector<ReportCase> cases =
      Misses(f.evaluation.runs[0], f.evaluation.truths[0], f.matrix, 100, threshold, 1000);
  ASSERT_EQ(cases.size(), missed.size());
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(cases[k].query, missed[k].query) << k;
    EXPECT_EQ(cases[k].answer, missed[k].answer) << k;
    EXPECT_EQ(cases[k].correct, missed[k].correct) << k;
  }
  // Right answers above the threshold are misses too (the queries with q % 3 == 2).
  EXPECT_TRUE(std::any_of(cases.begin(), cases.end(), [](const ReportCase& c) { return c.correct; }));
}

std::string Base64Decode(const std::string& text) {
  const std::string digits =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned value = 0;
  int bits = 0;
  for (const char c : text) {
    if (c == '=') break;
    const std::size_t d = digits.find(c);
    if (d == std::string::npos) ADD_FAILURE() << "not base64: " << c;
    value = (value << 6) | static_cast<unsigned>(d);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((value >> bits) & 0xFF);
    }
  }
  return out;
}

TEST(HtmlReport, PageIsSelfContainedWithEveryImageDecodable) {
  const Fixture f;
  ReportInput input;
  input.program = "test";
  input.title = "Report <of> test";
  input.settings = ChangedSettings(f.config);
  input.evaluation = &f.evaluation;
  input.matrices = {&f.matrix};
  input.examples = 4;
  int reads = 0;
  input.frames.read = [&](bool row, int index) {
    ++reads;
    EXPECT_TRUE(row ? index >= kFrames : index < kFrames) << row << " " << index;
    cv::Mat image(30, 50, CV_32FC3, cv::Scalar(0.2, 0.4, 0.6));
    return image;
  };
  input.frames.name = [](bool row, int index) {
    return std::string(row ? "q" : "r") + std::to_string(index) + ".png";
  };
  const std::string page = EncodeHtmlReport(input);

  for (const char* id :
       {"settings", "figures", "pr", "matrix", "explore", "wrong-matches", "misses"})
    EXPECT_NE(page.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
  EXPECT_NE(page.find("Report &lt;of&gt; test"), std::string::npos);
  EXPECT_NE(page.find("LDB &lt;b&gt;&amp;"), std::string::npos);
  EXPECT_EQ(page.find("LDB <b>&"), std::string::npos);
  // Nothing is fetched: no link, no external source.
  EXPECT_EQ(page.find("<link"), std::string::npos);
  EXPECT_EQ(page.find("http"), std::string::npos);
  // (std::regex recurses per character: a data URI of 100 kB would overflow the stack.)
  int images = 0, sheets = 0;
  for (std::size_t at = page.find("src=\""); at != std::string::npos;
       at = page.find("src=\"", at + 1)) {
    const std::size_t begin = at + 5;
    const std::string value = page.substr(begin, page.find('"', begin) - begin);
    const std::string png = "data:image/png;base64,", jpeg = "data:image/jpeg;base64,";
    const bool is_jpeg = value.compare(0, jpeg.size(), jpeg) == 0;
    ASSERT_TRUE(is_jpeg || value.compare(0, png.size(), png) == 0) << value.substr(0, 40);
    const std::string bytes = Base64Decode(value.substr((is_jpeg ? jpeg : png).size()));
    bool grey_alpha = false;
    const cv::Mat decoded =
        DecodeCommonFormat(std::vector<unsigned char>(bytes.begin(), bytes.end()), grey_alpha);
    EXPECT_FALSE(decoded.empty());
    if (is_jpeg) {
      // A thumbnail sheet of the explorer: 40 frames of 50 x 30 (at most 96 high) on one row
      // of 32 and one of 8.
      ++sheets;
      EXPECT_EQ(decoded.cols, 32 * 50);
      EXPECT_EQ(decoded.rows, 2 * 30);
    }
    ++images;
  }
  // The PR figure, one overlay, the explorer's matrix and its two thumbnail sheets (queries,
  // references), then three frames (query, answer, true place) per worst case: four wrong
  // matches and four misses, each with an answer and a true place.
  EXPECT_EQ(sheets, 2);
  EXPECT_EQ(images, 2 + 3 + 3 * (4 + 4));
  // The worst cases' frames, and each frame of the block once for the explorer.
  EXPECT_EQ(reads, 3 * (4 + 4) + 2 * kFrames);
  // The explorer's data: names of the frames, the run's best matches.
  EXPECT_NE(page.find("\"q79.png\""), std::string::npos);
  EXPECT_NE(page.find("\"r0.png\""), std::string::npos);
  // The figures table holds the run's AUC as computed.
  char auc[32];
  std::snprintf(auc, sizeof auc, "%.4f", f.evaluation.runs[0].per_query.auc);
  EXPECT_NE(page.find(std::string("<td class=\"n\">") + auc + "</td>"), std::string::npos);
  // The settings table names the keys changed from the defaults, and only those.
  EXPECT_NE(page.find("<code>Ground_truth_type</code>"), std::string::npos);
  EXPECT_EQ(page.find("<code>Image_descriptor</code>"), std::string::npos);
}

TEST(HtmlReport, WithoutFramesTheCasesAreNamedAndTheReasonGiven) {
  const Fixture f;
  ReportInput input;
  input.evaluation = &f.evaluation;
  input.matrices = {&f.matrix};
  input.frames.missing = "no frames given";
  const std::string page = EncodeHtmlReport(input);
  EXPECT_NE(page.find("Frames are named, not shown: no frames given"), std::string::npos);
  EXPECT_NE(page.find("row "), std::string::npos);
  int images = 0;
  for (std::size_t at = page.find("<img "); at != std::string::npos; at = page.find("<img ", at + 1))
    ++images;
  EXPECT_EQ(images, 3);  // the PR figure, the overlay, the explorer's matrix
}

// The text of the element `<script ... id="ID">TEXT</script>` of `page`.
std::string ScriptText(const std::string& page, const std::string& id) {
  const std::size_t at = page.find("id=\"" + id + "\">");
  if (at == std::string::npos) return "";
  const std::size_t begin = page.find('>', at) + 1;
  return page.substr(begin, page.find("</script>", begin) - begin);
}

// Frame names, a label, a title and settings that are not valid UTF-8: the page (which declares
// UTF-8) is valid UTF-8 and shows each byte outside a well-formed sequence as \xNN, then escaped
// for HTML as any text; in the explorer's data, the same text as a JSON string.
TEST(HtmlReport, TextThatIsNotUtf8IsShownAsEscapes) {
  Fixture f;
  f.evaluation.runs[0].label = "LDB \xe9<";
  ReportInput input;
  input.title = "run of caf\xe9";
  input.settings = {{"Images_path", "frames/\xed\xa0\x80"}};
  input.all_settings = "Images_path: frames/\xed\xa0\x80\n";
  input.evaluation = &f.evaluation;
  input.matrices = {&f.matrix};
  input.examples = 3;
  input.frames.name = [](bool row, int index) {
    return std::string(row ? "q\xe9" : "r\xc0\xaf") + std::to_string(index) + ".png";
  };
  input.frames.missing = "names only";
  const std::string page = EncodeHtmlReport(input);
  EXPECT_EQ(testing::FirstInvalidUtf8Byte(page), std::string::npos);
  EXPECT_NE(page.find("<title>run of caf\\xe9</title>"), std::string::npos);
  EXPECT_NE(page.find("<code>frames/\\xed\\xa0\\x80</code>"), std::string::npos);
  EXPECT_NE(page.find("<pre>Images_path: frames/\\xed\\xa0\\x80\n</pre>"), std::string::npos);
  EXPECT_NE(page.find("<h3>LDB \\xe9&lt;</h3>"), std::string::npos);
  const std::size_t query = page.find(".png<br>query ");
  ASSERT_NE(query, std::string::npos);
  EXPECT_EQ(page.compare(page.rfind('>', query) + 1, 5, "q\\xe9"), 0)
      << page.substr(page.rfind('>', query), 30);
  const std::string frames = ScriptText(page, "explore-frames");
  EXPECT_NE(frames.find("\"q\\\\xe9" + std::to_string(kFrames) + ".png\""), std::string::npos);
  EXPECT_NE(frames.find("\"r\\\\xc0\\\\xaf0.png\""), std::string::npos);
  const Json run = Json::parse(ScriptText(page, "explore-run-0"));
  EXPECT_EQ(run["label"], "LDB \\xe9<");
}

TEST(HtmlReport, ExplorerEmbedsEachQuerysBestMatchAndThe8BitBlock) {
  const Fixture f;
  ReportInput input;
  input.evaluation = &f.evaluation;
  input.matrices = {&f.matrix};
  input.frames.missing = "no frames given";
  const std::string page = EncodeHtmlReport(input);
  const Json run = Json::parse(ScriptText(page, "explore-run-0"));
  const std::vector<Expected> expected = BruteForce(f.matrix);
  ASSERT_EQ(run["queries"], kFrames);
  ASSERT_EQ(run["references"], kFrames);
  EXPECT_EQ(run["row_offset"], kFrames);
  EXPECT_EQ(run["score_kind"], "distance");
  for (int q = 0; q < kFrames; ++q) {
    EXPECT_EQ(run["best"][q], expected[q].answer) << q;
    EXPECT_FLOAT_EQ(run["distance"][q].get<float>(), expected[q].distance) << q;
    EXPECT_FLOAT_EQ(run["score"][q].get<float>(), expected[q].distance) << q;
    EXPECT_EQ(run["correct"].get<std::string>()[q], expected[q].correct ? '1' : '0') << q;
  }
  // The curve: one point per distinct score, (threshold, tp, fp).
  EXPECT_EQ(run["curve"].size(), f.evaluation.runs[0].per_query.curve.size());
  // The block, one byte per cell, row by row.
  EXPECT_EQ(run["values"]["cell_rows"], 1);
  const std::string codes = Base64Decode(ScriptText(page, "explore-values-0"));
  ASSERT_EQ(codes.size(), static_cast<std::size_t>(kFrames * kFrames));
  for (int q = 0; q < kFrames; ++q)
    for (int c = 0; c < kFrames; ++c) {
      const int code = static_cast<unsigned char>(codes[q * kFrames + c]);
      EXPECT_NEAR(code / 254.0, f.matrix(kFrames + q, c), 0.5 / 254 + 1e-6) << q << " " << c;
    }
  // Names without frames to read: rows and columns of the matrix.
  EXPECT_NE(ScriptText(page, "explore-frames").find("\"row 79\""), std::string::npos);
  EXPECT_NE(ScriptText(page, "explore-frames").find("\"column 0\""), std::string::npos);
}

TEST(HtmlReport, ExplorerCodesAndGroupsOfCells) {
  EXPECT_EQ(ExploreCode(0.0f), 0);
  EXPECT_EQ(ExploreCode(1.0f), 254);
  EXPECT_EQ(ExploreCode(0.5f), 127);
  EXPECT_EQ(ExploreCode(2.0f), 254);
  EXPECT_EQ(ExploreCode(-1.0f), 0);
  EXPECT_EQ(ExploreCode(std::numeric_limits<float>::quiet_NaN()), 255);
  EXPECT_EQ(ExploreCode(std::numeric_limits<float>::infinity()), 255);
  // A block taller than kExploreValuesSide: rows go by groups, each the mean of its finite
  // cells; a group without one has no value.
  const int rows = kExploreValuesSide * 2 + 7, cols = 3;
  cv::Mat1f m(rows + 1, cols + 2, 0.9f);  // one row and two columns outside the block
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m(1 + r, 2 + c) = static_cast<float>((r % 3) * 0.25 + c * 0.1);
  for (int r = 0; r < 3; ++r) m(1 + r, 2) = std::numeric_limits<float>::infinity();
  const EvaluationLayout layout{EvaluationLayout::Kind::kQueryReference, rows, cols, 1, 2};
  int cell_rows = 0, cell_cols = 0;
  const cv::Mat1b values = ExploreValues(m, layout, cell_rows, cell_cols);
  EXPECT_EQ(cell_rows, 3);
  EXPECT_EQ(cell_cols, 1);
  ASSERT_EQ(values.rows, (rows + 2) / 3);
  ASSERT_EQ(values.cols, cols);
  EXPECT_EQ(values(0, 0), 255);                     // rows 0-2 of column 0 have no value
  EXPECT_EQ(values(1, 0), ExploreCode(0.25f));      // rows 3-5: 0, 0.25, 0.5
  EXPECT_EQ(values(1, 2), ExploreCode(0.45f));      // plus 0.2
  EXPECT_EQ(values(values.rows - 1, 1), ExploreCode(0.225f));  // the last group: 2 rows (0.1, 0.35)
}

TEST(HtmlReport, ChangedSettingsAreTheKeysDifferentFromTheDefaults) {
  Config config;
  EXPECT_TRUE(ChangedSettings(config).empty());
  ApplyOverride(config, "Image_sequences=7");
  ApplyOverride(config, "Report_name=r.html");
  const auto changed = ChangedSettings(config);
  ASSERT_EQ(changed.size(), 2u);
  EXPECT_EQ(changed[0], std::make_pair(std::string("Image_sequences"), std::string("7")));
  EXPECT_EQ(changed[1].first, "Report_name");
}

}  // namespace
}  // namespace openable
