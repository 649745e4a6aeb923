#include "OpenABLE/reports/html_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/report.h"
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
  const std::vector<ReportCase> cases =
      ConfidentWrongMatches(f.evaluation.runs[0], f.evaluation.truths[0], f.matrix, 100, 5);
  ASSERT_EQ(cases.size(), 5u);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(cases[k].query, wrong[k].query) << k;
    EXPECT_EQ(cases[k].answer, wrong[k].answer) << k;
    EXPECT_FLOAT_EQ(cases[k].score, wrong[k].distance) << k;
    EXPECT_FALSE(cases[k].correct);
    EXPECT_EQ(cases[k].true_place, wrong[k].query);  // aligned: query i is reference i
  }
  EXPECT_TRUE(ConfidentWrongMatches(f.evaluation.runs[0], f.evaluation.truths[0], f.matrix, 100, 0)
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
  EXPECT_TRUE(
      std::any_of(cases.begin(), cases.end(), [](const ReportCase& c) { return c.correct; }));
}

std::string Base64Decode(const std::string& text) {
  const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
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
  for (std::size_t at = page.find("<img "); at != std::string::npos;
       at = page.find("<img ", at + 1))
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
  EXPECT_EQ(values(0, 0), 255);                                // rows 0-2 of column 0 have no value
  EXPECT_EQ(values(1, 0), ExploreCode(0.25f));                 // rows 3-5: 0, 0.25, 0.5
  EXPECT_EQ(values(1, 2), ExploreCode(0.45f));                 // plus 0.2
  EXPECT_EQ(values(values.rows - 1, 1), ExploreCode(0.225f));  // the last group: 2 rows (0.1, 0.35)
}

// The ids of the page's sections, in order.
std::vector<std::string> Sections(const std::string& page) {
  std::vector<std::string> ids;
  const std::string open = "<section id=\"";
  for (std::size_t at = page.find(open); at != std::string::npos; at = page.find(open, at + 1)) {
    const std::size_t begin = at + open.size();
    ids.push_back(page.substr(begin, page.find('"', begin) - begin));
  }
  return ids;
}

// The page without its scripts (the text and markup a reader sees).
std::string WithoutScripts(std::string page) {
  for (std::size_t at = page.find("<script"); at != std::string::npos; at = page.find("<script")) {
    const std::size_t end = page.find("</script>", at);
    page.erase(at, end + 9 - at);
  }
  return page;
}

// The data-query of each row of the table `<table class="cases" data-kind="KIND">`.
std::vector<int> CaseQueries(const std::string& page, const std::string& kind) {
  std::vector<int> out;
  const std::size_t table = page.find("data-kind=\"" + kind + "\"");
  if (table == std::string::npos) return out;
  const std::size_t end = page.find("</table>", table);
  for (std::size_t at = page.find("data-query=\"", table); at < end;
       at = page.find("data-query=\"", at + 1))
    out.push_back(std::stoi(page.substr(at + 12)));
  return out;
}

// The number in the cell `column` (0-based) of the first data row of the table with `id`.
std::string Cell(const std::string& page, const std::string& id, int column) {
  std::size_t at = page.find("<table id=\"" + id + "\"");
  at = page.find("<tr", page.find("</tr>", at));
  for (int c = 0; c <= column; ++c) at = page.find("<td", at + 1);
  const std::size_t begin = page.find('>', at) + 1;
  return page.substr(begin, page.find("</td>", begin) - begin);
}

// A queries x references matrix taken whole (as a map's query block): 30 queries against 50
// references, query q's place reference q + 10 small for most queries (distances 0.1 + q / 1000,
// accepted at 0.3), random elsewhere, query 4 without any cell with a value.
struct BlockFixture {
  static constexpr int kQueries = 30, kReferences = 50;
  cv::Mat1f matrix;
  EvaluationOptions options;
  struct Expected {
    int best = -1;
    float distance = 0;
  };
  std::vector<Expected> expected;  // by brute force

  BlockFixture() {
    matrix.create(kQueries, kReferences);
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0.35f, 1.0f);
    for (int q = 0; q < kQueries; ++q)
      for (int c = 0; c < kReferences; ++c) matrix(q, c) = u(rng);
    for (int q = 0; q < kQueries; ++q)
      if (q % 5 != 2) matrix(q, q + 10) = 0.1f + 0.001f * static_cast<float>((q * 7) % 30);
    for (int c = 0; c < kReferences; ++c) matrix(4, c) = std::numeric_limits<float>::infinity();
    options.accept_threshold = 0.3;
    for (int q = 0; q < kQueries; ++q) {
      Expected e;
      for (int c = 0; c < kReferences; ++c)
        if (std::isfinite(matrix(q, c)) && (e.best < 0 || matrix(q, c) < matrix(q, e.best)))
          e.best = c;
      if (e.best >= 0) e.distance = matrix(q, e.best);
      expected.push_back(e);
    }
  }

  ReportInput Input(const ReportAnswers& answers) const {
    ReportInput input;
    input.program = "openable_map";
    input.title = "Queries of a map";
    input.settings = {{"map", "route.map"}};
    input.answers = {answers};
    input.matrices = {&matrix};
    input.examples = 4;
    input.frames.read = [](bool row, int index) {
      return cv::Mat(24, 40, CV_32FC1, cv::Scalar(row ? 0.25 : 0.75 - index / 100.0));
    };
    input.frames.name = [](bool row, int index) {
      return std::string(row ? "query-" : "place-") + std::to_string(index) + ".png";
    };
    return input;
  }
};

TEST(HtmlReport, WithoutGroundTruthTheRunsAnswersAndAcceptedFramesAreShown) {
  const BlockFixture f;
  const ReportAnswers answers = AnswersForReport(f.matrix, EvaluationLayout::QueryReference(30, 50),
                                                 "LDB L=1", "a map", f.options);
  // Accepted (distance <= 0.3) by brute force, most confident first.
  std::vector<int> accepted;
  for (int q = 0; q < 30; ++q)
    if (f.expected[q].best >= 0 && f.expected[q].distance <= 0.3f) accepted.push_back(q);
  std::stable_sort(accepted.begin(), accepted.end(),
                   [&](int a, int b) { return f.expected[a].distance < f.expected[b].distance; });
  ASSERT_EQ(accepted.size(), 23u);  // 24 with the place, less query 4
  ReportInput input = f.Input(answers);
  int reads = 0;
  const auto read = input.frames.read;
  input.frames.read = [&](bool row, int index) {
    ++reads;
    return read(row, index);
  };
  std::vector<std::pair<std::int64_t, std::int64_t>> progress;
  input.on_progress = [&](std::int64_t done, std::int64_t total) {
    progress.emplace_back(done, total);
  };
  const std::string page = EncodeHtmlReport(input);

  EXPECT_EQ(Sections(page), (std::vector<std::string>{"settings", "operating-point", "matrix",
                                                      "explore", "accepted"}));
  // It says there is no ground truth, and how to get figures.
  EXPECT_NE(page.find("<b>No ground truth.</b>"), std::string::npos);
  EXPECT_NE(page.find("Ground_truth_type"), std::string::npos);
  // Nothing is judged: no figures, no right or wrong, no precision or recall in what is shown.
  const std::string shown = WithoutScripts(page);
  for (const char* judged : {"figures-table", "class=\"right\"", "class=\"wrong\"", "ex-precision",
                             "ex-recall", "ex-correct", "precision-recall figure", "true place",
                             ">right<", ">wrong<", "<th>result</th>"})
    EXPECT_EQ(shown.find(judged), std::string::npos) << judged;
  // The operating point: 29 answered, 23 accepted, all confirmed (no Match_consistency).
  EXPECT_EQ(Cell(page, "operating-point-table", 1), "30");
  EXPECT_EQ(Cell(page, "operating-point-table", 2), "29");
  EXPECT_EQ(Cell(page, "operating-point-table", 5), "23");
  EXPECT_EQ(Cell(page, "operating-point-table", 7), "23");
  EXPECT_NE(page.find(": the run&#39;s 23 matches."), std::string::npos);
  // The most confident accepted matches, then the least confident, least confident first.
  const std::vector<int> confident(accepted.begin(), accepted.begin() + 4);
  const std::vector<int> doubtful(accepted.rbegin(), accepted.rbegin() + 4);
  EXPECT_EQ(CaseQueries(page, "accepted-confident"), confident);
  EXPECT_EQ(CaseQueries(page, "accepted-doubtful"), doubtful);
  // Each row shows the query's frame beside its matched frame, by name, with its distance.
  for (const int q : confident) {
    const std::size_t row =
        page.find("<tr data-query=\"" + std::to_string(q) + "\" data-reference=\"" +
                  std::to_string(f.expected[q].best) + "\">");
    ASSERT_NE(row, std::string::npos) << q;
    const std::string text = page.substr(row, page.find("</tr>", row) - row);
    EXPECT_NE(text.find("query-" + std::to_string(q) + ".png"), std::string::npos) << text;
    EXPECT_NE(text.find("place-" + std::to_string(f.expected[q].best) + ".png"), std::string::npos);
    EXPECT_NE(text.find("distance " + FormatFixed(f.expected[q].distance, 4)), std::string::npos)
        << text;
  }
  // The explorer's data: no truth, each query's best match, the run's accepted answers.
  const Json run = Json::parse(ScriptText(page, "explore-run-0"));
  EXPECT_EQ(run["truth"], false);
  EXPECT_EQ(run["correct"], "");
  EXPECT_EQ(run["row_offset"], 0);
  EXPECT_EQ(run["col_offset"], 0);
  std::string digits(30, '0');
  for (const int q : accepted) digits[q] = '1';
  EXPECT_EQ(run["accepted"], digits);
  for (int q = 0; q < 30; ++q) EXPECT_EQ(run["best"][q], f.expected[q].best) << q;
  // Frames: the explorer's thumbnails of 30 queries and 50 references once each, and two per
  // case (4 + 4 cases); the frame images on the page: 16.
  EXPECT_EQ(reads, 30 + 50 + 2 * 8);
  int frames = 0;
  for (std::size_t at = page.find("class=\"frame\""); at != std::string::npos;
       at = page.find("class=\"frame\"", at + 1))
    ++frames;
  EXPECT_EQ(frames, 16);
  // Progress: from 0 to its total, one step at a time.
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.front().first, 0);
  EXPECT_EQ(progress.back().first, progress.back().second);
  EXPECT_EQ(progress.size(), static_cast<std::size_t>(progress.back().second) + 1);
  EXPECT_GE(progress.back().second, 30 + 50);
}

TEST(HtmlReport, WithoutGroundTruthARunThatAcceptsNothingSaysWhy) {
  const BlockFixture f;
  EvaluationOptions none = f.options;
  none.accept_threshold = -1;
  ReportAnswers answers = AnswersForReport(f.matrix, EvaluationLayout::QueryReference(30, 50),
                                           "LDB L=1", "a map", none);
  ReportInput input = f.Input(answers);
  input.truth_advice = "Give openable_map a ground truth.";
  std::string page = EncodeHtmlReport(input);
  EXPECT_NE(page.find("Give openable_map a ground truth."), std::string::npos);
  EXPECT_EQ(page.find("Ground_truth_type and Ground_truth"), std::string::npos);
  EXPECT_NE(page.find("No match accepted: Match_threshold is not set (-1)"), std::string::npos);
  EXPECT_NE(page.find("Most confident best matches"), std::string::npos);
  // The most confident best matches stand in for the accepted ones.
  EXPECT_EQ(CaseQueries(page, "accepted-confident").size(), 4u);
  EXPECT_EQ(page.find("UNRELIABLE"), std::string::npos);

  // The auto mode trusted no setting: UNRELIABLE, nothing accepted.
  EvaluationOptions untrusted = f.options;
  untrusted.accept_none = true;
  input.answers = {AnswersForReport(f.matrix, EvaluationLayout::QueryReference(30, 50), "SAD",
                                    "a run", untrusted)};
  page = EncodeHtmlReport(input);
  EXPECT_NE(page.find("UNRELIABLE: the auto mode could not trust any candidate"),
            std::string::npos);
  EXPECT_EQ(Cell(page, "operating-point-table", 7), "0");
  EXPECT_NE(page.find("\"accepted\":\"" + std::string(30, '0') + "\""), std::string::npos);
}

TEST(HtmlReport, WithoutGroundTruthAnswersThatDoNotFitAreRefused) {
  const BlockFixture f;
  ReportAnswers answers =
      AnswersForReport(f.matrix, EvaluationLayout::QueryReference(30, 50), "x", "y", f.options);
  ReportInput input = f.Input(answers);
  input.matrices.clear();
  EXPECT_THROW(EncodeHtmlReport(input), std::logic_error);
  input = f.Input(answers);
  input.answers[0].answers.confirmed.pop_back();
  EXPECT_THROW(EncodeHtmlReport(input), std::logic_error);
  input = f.Input(answers);
  input.answers[0].answers.best[3] = 50;  // not a column of the block
  EXPECT_THROW(EncodeHtmlReport(input), std::logic_error);
  input = f.Input(answers);
  input.answers[0].layout = EvaluationLayout::QueryReference(31, 50);
  EXPECT_THROW(EncodeHtmlReport(input), std::logic_error);
}

// With ground truth and Match_threshold, the figures show the run's operating point (accepted,
// confirmed, right, precision, recall) and, with Evaluation_protocol naming them, one row per
// reference protocol, as the text table prints them.
TEST(HtmlReport, FiguresShowTheOperatingPointAndTheReferenceProtocols) {
  Config config;
  ApplyOverride(config, "Ground_truth_type=aligned");
  ApplyOverride(config, "Tolerance=" + std::to_string(kTolerance));
  ApplyOverride(config, "Match_threshold=0.55");
  ApplyOverride(config, "Evaluation_protocol=all");
  Fixture base;
  Evaluation evaluation;
  evaluation.settings = EvaluationSettingsFrom(config);
  EvaluateMatrix(evaluation, base.matrix, EvaluationLayout::TwoTraversals(kFrames, kFrames), "LDB",
                 "test");
  // By brute force: answers with distance <= 0.55, and the right ones among them.
  int accepted = 0, right = 0;
  for (const Expected& e : BruteForce(base.matrix))
    if (e.distance <= 0.55f) {
      ++accepted;
      right += e.correct;
    }
  ASSERT_GT(right, 0);
  ASSERT_LT(right, accepted);  // some accepted answers are wrong
  ReportInput input;
  input.evaluation = &evaluation;
  input.matrices = {&base.matrix};
  input.frames.missing = "none";
  const std::string page = EncodeHtmlReport(input);
  EXPECT_EQ(Sections(page), (std::vector<std::string>{"settings", "figures", "pr", "matrix",
                                                      "explore", "wrong-matches", "misses"}));
  EXPECT_EQ(page.find("No ground truth"), std::string::npos);
  EXPECT_EQ(Cell(page, "operating-point-table", 5), std::to_string(accepted));
  EXPECT_EQ(Cell(page, "operating-point-table", 7), std::to_string(accepted));
  EXPECT_EQ(Cell(page, "operating-point-table", 8), std::to_string(right));
  EXPECT_EQ(Cell(page, "operating-point-table", 9), FormatFixed(double(right) / accepted, 4));
  // One row per protocol, with the figures the text table prints.
  const std::string text = FormatEvaluationTable(evaluation.settings, evaluation.runs);
  for (const char* protocol : {"openable", "vpr_bench", "vpr_tutorial"}) {
    EXPECT_NE(page.find("<tr data-protocol=\"" + std::string(protocol) + "\">"), std::string::npos)
        << protocol;
    EXPECT_NE(text.find(protocol), std::string::npos);
  }
  ASSERT_EQ(evaluation.runs[0].reference.size(), 2u);
  const ProtocolFigures& b = evaluation.runs[0].reference[0];
  ASSERT_EQ(b.protocol, "vpr_bench");
  const std::size_t row = page.find("<tr data-protocol=\"vpr_bench\">");
  EXPECT_NE(page.find("<td class=\"n\">" + FormatFixed(b.auc, 4) + "</td>", row),
            std::string::npos);
  EXPECT_NE(text.find(FormatFixed(b.auc, 3)), std::string::npos);
  // The text table's operating point names the right answers too.
  EXPECT_NE(text.find(std::to_string(accepted) + " answers, " + std::to_string(right) + " right"),
            std::string::npos)
      << text;
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
