#include "OpenABLE/reports/html_report.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "OpenABLE/io/image_codec.h"
#include "config/config.h"

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

  for (const char* id : {"settings", "figures", "pr", "matrix", "wrong-matches", "misses"})
    EXPECT_NE(page.find("<section id=\"" + std::string(id) + "\">"), std::string::npos) << id;
  EXPECT_NE(page.find("Report &lt;of&gt; test"), std::string::npos);
  EXPECT_NE(page.find("LDB &lt;b&gt;&amp;"), std::string::npos);
  EXPECT_EQ(page.find("LDB <b>&"), std::string::npos);
  // Nothing is fetched: no link, no external source.
  EXPECT_EQ(page.find("<link"), std::string::npos);
  EXPECT_EQ(page.find("http"), std::string::npos);
  // (std::regex recurses per character: a data URI of 100 kB would overflow the stack.)
  int images = 0;
  for (std::size_t at = page.find("src=\""); at != std::string::npos;
       at = page.find("src=\"", at + 1)) {
    const std::size_t begin = at + 5;
    const std::string value = page.substr(begin, page.find('"', begin) - begin);
    const std::string prefix = "data:image/png;base64,";
    ASSERT_EQ(value.compare(0, prefix.size(), prefix), 0) << value.substr(0, 40);
    const std::string bytes = Base64Decode(value.substr(prefix.size()));
    cv::Mat decoded;
    std::string why;
    EXPECT_TRUE(DecodePng(std::vector<unsigned char>(bytes.begin(), bytes.end()), decoded, why))
        << why;
    EXPECT_FALSE(decoded.empty());
    ++images;
  }
  // The PR figure, one overlay, then three frames (query, answer, true place) per worst case:
  // four wrong matches and four misses, each with an answer and a true place.
  EXPECT_EQ(images, 2 + 3 * (4 + 4));
  EXPECT_EQ(reads, 3 * (4 + 4));
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
  EXPECT_EQ(images, 2);
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
