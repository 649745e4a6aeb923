#include "OpenABLE/reports/html_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/reports/evaluation_files.h"
#include "OpenABLE/reports/figures.h"
#include "OpenABLE/reports/html_explorer.h"
#include "OpenABLE/reports/html_text.h"
#include "config/config.h"

namespace openable {
namespace {

constexpr int kThumbnailWidth = 320;  // frames of the worst cases, pixels across at most

std::string Escape(const std::string& text) { return HtmlEscape(text); }

// `value` with `decimals` digits after the point; a dash when it is not finite.
std::string Number(double value, int decimals) {
  return std::isfinite(value) ? FormatFixed(value, decimals) : "&ndash;";
}

std::string PngImage(const cv::Mat& image, const std::string& css_class, const std::string& alt) {
  return "<img class=\"" + css_class + "\" alt=\"" + Escape(alt) +
         "\" src=\"data:image/png;base64," + Base64(EncodePng(image)) + "\">";
}

// A frame as an 8-bit BGR thumbnail at most kThumbnailWidth pixels across.
cv::Mat Thumbnail(const cv::Mat& frame) {
  cv::Mat image = frame;
  if (image.channels() == 2) {  // a stereo pair with its disparity: the grey image
    cv::Mat first;
    cv::extractChannel(image, first, 0);
    image = first;
  }
  if (image.depth() != CV_8U) image.convertTo(image, CV_8U, 255.0);
  if (image.cols > kThumbnailWidth) {
    const int height =
        std::max(1, static_cast<int>(std::lround(image.rows * double(kThumbnailWidth) / image.cols)));
    cv::resize(image, image, cv::Size(kThumbnailWidth, height), 0, 0, cv::INTER_AREA);
  }
  return image;
}

// Query q's ground-truth candidate with the smallest distance in `matrix`, -1 when none.
int TruePlace(const EvaluatedRun& run, const GroundTruth& truth, const cv::Mat1f& matrix,
              int exclusion, int q) {
  const EvaluationLayout& layout = run.layout;
  const int end = layout.CandidateEnd(q, exclusion);
  int best = -1;
  float best_distance = std::numeric_limits<float>::infinity();
  for (const int c : truth.matches.at(q)) {
    if (c >= end) break;  // sorted
    const float d = matrix(layout.row_offset + q, layout.col_offset + c);
    if (best < 0 || d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

ReportCase CaseOf(const EvaluatedRun& run, const GroundTruth& truth, const cv::Mat1f& matrix,
                  int exclusion, int q) {
  const PerQueryResult& p = run.per_query;
  ReportCase c;
  c.query = q;
  c.answer = p.best[q];
  c.score = c.answer >= 0 ? p.score[q] : std::numeric_limits<float>::infinity();
  c.correct = c.answer >= 0 && p.correct[q] != 0;
  c.true_place = TruePlace(run, truth, matrix, exclusion, q);
  return c;
}

struct Frame {
  bool row;
  int index;  // in the full matrix
};

}  // namespace

std::vector<ReportCase> ConfidentWrongMatches(const EvaluatedRun& run, const GroundTruth& truth,
                                              const cv::Mat1f& matrix, int exclusion, int n) {
  const PerQueryResult& p = run.per_query;
  std::vector<int> queries;
  for (int q = 0; q < static_cast<int>(p.best.size()); ++q)
    if (p.best[q] >= 0 && !p.correct[q]) queries.push_back(q);
  std::stable_sort(queries.begin(), queries.end(),
                   [&](int a, int b) { return p.score[a] < p.score[b]; });
  if (static_cast<int>(queries.size()) > n) queries.resize(std::max(0, n));
  std::vector<ReportCase> out;
  for (const int q : queries) out.push_back(CaseOf(run, truth, matrix, exclusion, q));
  return out;
}

std::vector<ReportCase> Misses(const EvaluatedRun& run, const GroundTruth& truth,
                               const cv::Mat1f& matrix, int exclusion, double threshold, int n) {
  const PerQueryResult& p = run.per_query;
  std::vector<ReportCase> all;
  for (int q = 0; q < static_cast<int>(p.best.size()); ++q) {
    if (!p.positive[q]) continue;
    // At the operating point, the answers it accepted (Match_consistency may refuse some
    // below the threshold; an untrusted auto run accepts none).
    const bool accepted = p.has_operating_point && q < static_cast<int>(p.accepted.size())
                              ? p.accepted[q] != 0
                              : p.score[q] <= threshold;
    const bool found = p.best[q] >= 0 && p.correct[q] && accepted;
    if (!found) all.push_back(CaseOf(run, truth, matrix, exclusion, q));
  }
  // Unanswered first (score +inf), then the least confident.
  std::stable_sort(all.begin(), all.end(),
                   [](const ReportCase& a, const ReportCase& b) { return a.score > b.score; });
  if (static_cast<int>(all.size()) > n) all.resize(std::max(0, n));
  return all;
}

ReportFrames FramesFromSources(std::vector<std::unique_ptr<FrameSource>> sources,
                               bool rows_are_second) {
  auto shared = std::make_shared<std::vector<std::unique_ptr<FrameSource>>>(std::move(sources));
  // (source, frame of that source) of row or column `index`.
  const auto locate = [shared, rows_are_second](bool row, int index) {
    const auto& s = *shared;
    if (rows_are_second && s.size() == 2) return std::make_pair(s[row ? 1 : 0].get(), index);
    for (const auto& source : s) {
      if (index < source->Size()) return std::make_pair(source.get(), index);
      index -= source->Size();
    }
    throw std::out_of_range("FramesFromSources: frame beyond the sources");
  };
  ReportFrames frames;
  frames.same_rows_and_columns = !rows_are_second || shared->size() != 2;
  frames.read = [locate](bool row, int index) {
    const auto [source, i] = locate(row, index);
    return source->Read(i);
  };
  frames.name = [locate](bool row, int index) {
    const auto [source, i] = locate(row, index);
    return std::filesystem::path(source->FrameName(i)).filename().string();
  };
  return frames;
}

std::vector<std::pair<std::string, std::string>> ChangedSettings(const Config& config) {
  const Config defaults;
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& key : ConfigKeyNames()) {
    const std::string value = ConfigValueText(config, key);
    if (value != ConfigValueText(defaults, key)) out.emplace_back(key, value);
  }
  return out;
}

namespace {

// The two sections of worst cases (most confident wrong matches, misses), one table per run,
// with the frames when the report can read them.
std::string WorstCaseSections(const ReportInput& input) {
  const Evaluation& evaluation = *input.evaluation;
  const int exclusion = evaluation.settings.options.exclusion;
  std::string h;
  const ReportFrames& frames = input.frames;
  const auto frame_name = [&](Frame f) {
    if (frames.name) return frames.name(f.row, f.index);
    return std::string(f.row ? "row " : "column ") + std::to_string(f.index);
  };
  const auto cell = [&](const EvaluatedRun& run, bool query, int block_index,
                        const std::string& what, const std::string& css) {
    if (block_index < 0) return "<td class=\"note\">" + what + "</td>";
    const Frame f = query ? Frame{true, run.layout.row_offset + block_index}
                          : Frame{false, run.layout.col_offset + block_index};
    std::string c = "<td class=\"" + css + "\">";
    if (frames.read)
      c += PngImage(Thumbnail(frames.read(f.row, f.index)), "frame", frame_name(f));
    c += Escape(frame_name(f)) + "<br>" + (query ? "query " : "reference ") +
         std::to_string(block_index) + "</td>";
    return c;
  };
  const auto cases_table = [&](const EvaluatedRun& run, const cv::Mat1f& matrix,
                               const std::vector<ReportCase>& cases, const std::string& kind) {
    std::string t = "<h3>" + Escape(run.label) + "</h3>\n";
    if (cases.empty()) return t + "<p class=\"note\">None.</p>\n";
    t += "<table class=\"cases\" data-kind=\"" + kind + "\">\n<tr><th>#</th><th>query</th><th>" +
         (kind == "wrong" ? "wrong match" : "best match") + "</th><th>true place</th></tr>\n";
    for (std::size_t k = 0; k < cases.size(); ++k) {
      const ReportCase& c = cases[k];
      const auto distance = [&](int column) {
        return Number(matrix(run.layout.row_offset + c.query, run.layout.col_offset + column), 4);
      };
      std::string score = c.answer >= 0 ? "score " + Number(c.score, 4) + "<br>match: " +
                                              distance(c.answer)
                                        : std::string("no answer");
      if (c.true_place >= 0) score += "<br>true place: " + distance(c.true_place);
      t += "<tr data-query=\"" + std::to_string(c.query) + "\"><td>" + std::to_string(k + 1) +
           "<br>" + score + "</td>" + cell(run, true, c.query, "", "") +
           cell(run, false, c.answer, "no answer", c.correct ? "right" : "wrong") +
           cell(run, false, c.true_place, "no true place among the candidates", "right") +
           "</tr>\n";
    }
    return t + "</table>\n";
  };
  const std::string no_images =
      frames.read ? ""
                  : "<p class=\"note\">Frames are named, not shown: " + Escape(frames.missing) +
                        "</p>\n";
  // One section per kind of worst case, one table per run.
  const auto cases_section = [&](const std::string& id, const std::string& title,
                                 const std::string& note, const std::string& kind,
                                 const auto& select) {
    std::string section = "<section id=\"" + id + "\">\n<h2>" + title +
                          "</h2>\n<p class=\"note\">" + note + "</p>\n" + no_images;
    for (std::size_t i = 0; i < evaluation.runs.size(); ++i)
      section += cases_table(evaluation.runs[i], *input.matrices[i],
                             select(evaluation.runs[i], evaluation.truths[i], *input.matrices[i]),
                             kind);
    return section + "</section>\n";
  };
  h += cases_section(
      "wrong-matches", "Most confident wrong matches",
      "Queries whose best match is not a true place (outside the tolerance), lowest score "
      "first: the wrong loops a threshold would accept first. Beside each, the true place: the "
      "query's ground-truth candidate with the smallest distance.",
      "wrong", [&](const EvaluatedRun& run, const GroundTruth& truth, const cv::Mat1f& m) {
        return ConfidentWrongMatches(run, truth, m, exclusion, input.examples);
      });
  h += cases_section(
      "misses", "Misses",
      "Queries with a true place that the run does not find at its operating point "
      "(Match_threshold, else the max-F1 threshold): no answer, a wrong answer, or a right one "
      "with a score above the threshold; least confident first.",
      "miss", [&](const EvaluatedRun& run, const GroundTruth& truth, const cv::Mat1f& m) {
        return Misses(run, truth, m, exclusion, OperatingThreshold(run), input.examples);
      });
  return h;
}

}  // namespace

std::string EncodeHtmlReport(const ReportInput& input) {
  const Evaluation& evaluation = *input.evaluation;
  if (input.matrices.size() != evaluation.runs.size())
    throw std::logic_error("EncodeHtmlReport: one matrix per run expected");
  const EvaluationSettings& s = evaluation.settings;
  const int exclusion = s.options.exclusion;

  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       "<meta name=\"generator\" content=\"OpenABLE " + std::string(kVersion) + "\">\n"
       "<title>" + Escape(input.title) + "</title>\n<style>\n"
       "body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1460px;padding:0 1em;"
       "color:#222}\n"
       "h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ddd}\n"
       "table{border-collapse:collapse;margin:.5em 0}\n"
       "th,td{border:1px solid #ccc;padding:3px 8px;text-align:left}\n"
       "th{background:#f3f3f3}td.n{text-align:right;font-variant-numeric:tabular-nums}\n"
       "img.figure{max-width:100%;border:1px solid #ddd}\n"
       "table.cases td{vertical-align:top;text-align:center}\n"
       "table.cases img{display:block;margin:0 auto 2px;width:260px;height:auto;"
       "image-rendering:pixelated}\n"
       ".wrong{color:#b00000}.right{color:#006400}.note{color:#555}\n"
       "pre{background:#f7f7f7;padding:.5em;overflow:auto;font-size:.85em}\n"
       // The explorer (html_explorer.h).
       ".ex-controls{margin:.5em 0;line-height:1.8}.ex-threshold{width:360px;vertical-align:middle}\n"
       ".ex-row{display:flex;flex-wrap:wrap;gap:1.2em;align-items:flex-start}\n"
       ".ex-matrix{position:relative;flex:none;cursor:crosshair;outline:1px solid #ccc}\n"
       ".ex-matrix:focus{outline:2px solid #ffb000}\n"
       ".ex-image{display:block;width:100%;height:100%;image-rendering:pixelated}\n"
       ".ex-overlay{position:absolute;left:0;top:0;width:100%;height:100%;pointer-events:none}\n"
       ".ex-side{max-width:420px}.ex-cell{margin-top:.5em;line-height:1.5}\n"
       ".ex-cell-frames canvas{height:96px;margin:0 6px 4px 0;border:1px solid #ccc;"
       "image-rendering:pixelated}\n"
       "table.ex-queries td{vertical-align:middle}table.ex-queries tbody tr{cursor:pointer}\n"
       "table.ex-queries canvas{height:48px;display:block;image-rendering:pixelated}\n"
       "</style>\n</head>\n<body>\n";
  h += "<h1>" + Escape(input.title) + "</h1>\n";
  h += "<p class=\"note\">Written by " + Escape(input.program) + " (OpenABLE " + kVersion +
       "). Figures and protocols: docs/evaluation.md; this page: docs/output_formats.md.</p>\n";
  std::string extra_links;
  for (const ReportTable& t : input.tables)
    extra_links += "<a href=\"#" + Escape(t.id) + "\">" + Escape(t.title) + "</a> &middot; ";
  h += "<nav><a href=\"#settings\">Settings</a> &middot; " + extra_links +
       "<a href=\"#figures\">Figures</a> "
       "&middot; <a href=\"#pr\">Precision-recall</a> &middot; <a href=\"#matrix\">Matrix</a> "
       "&middot; <a href=\"#explore\">Explore</a> &middot; <a href=\"#wrong-matches\">Wrong matches</a> &middot; "
       "<a href=\"#misses\">Misses</a></nav>\n";

  // Settings.
  h += "<section id=\"settings\">\n<h2>Settings</h2>\n<table id=\"settings-table\">\n"
       "<tr><th>setting</th><th>value</th></tr>\n";
  std::vector<std::pair<std::string, std::string>> protocol = {
      {"ground truth", GroundTruthTypeName(s.truth.type) +
                           (s.truth.path.empty() ? "" : " (" + s.truth.path + ")")},
      {"tolerance", "&plusmn;" + std::to_string(s.options.tolerance) + " frames"},
      {"match score", s.options.score == MatchScore::kRatio ? "ratio" : "distance"},
      {"ABLE-P vicinity", std::to_string(s.options.vicinity) + " frames"}};
  if (!evaluation.runs.empty() &&
      evaluation.runs[0].layout.kind == EvaluationLayout::Kind::kLoopClosure)
    protocol.insert(protocol.begin() + 2,
                    {"exclusion", std::to_string(exclusion) + " frames"});
  for (const auto& [key, value] : protocol)
    h += "<tr><td>" + key + "</td><td>" + (key == "tolerance" ? value : Escape(value)) +
         "</td></tr>\n";
  for (const auto& [key, value] : input.settings)
    h += "<tr><td><code>" + Escape(key) + "</code></td><td><code>" + Escape(value) +
         "</code></td></tr>\n";
  h += "</table>\n";
  if (!input.settings.empty())
    h += "<p class=\"note\">Keys of Config.txt shown above: those that differ from the "
         "defaults.</p>\n";
  if (!input.all_settings.empty())
    h += "<details><summary>Every key</summary>\n<pre>" + Escape(input.all_settings) +
         "</pre>\n</details>\n";
  h += "</section>\n";

  // Tables of the run (the auto mode's candidates).
  for (const ReportTable& t : input.tables) {
    h += "<section id=\"" + Escape(t.id) + "\">\n<h2>" + Escape(t.title) + "</h2>\n<table id=\"" +
         Escape(t.id) + "-table\">\n<tr>";
    for (const std::string& c : t.header) h += "<th>" + Escape(c) + "</th>";
    h += "</tr>\n";
    for (size_t r = 0; r < t.rows.size(); ++r) {
      h += static_cast<int>(r) == t.highlight ? "<tr style=\"font-weight:bold\">" : "<tr>";
      for (size_t c = 0; c < t.rows[r].size(); ++c)
        h += std::string(c < t.numeric.size() && t.numeric[c] ? "<td class=\"n\">" : "<td>") +
             Escape(t.rows[r][c]) + "</td>";
      h += "</tr>\n";
    }
    h += "</table>\n";
    if (!t.note.empty()) h += "<p class=\"note\">" + Escape(t.note) + "</p>\n";
    h += "</section>\n";
  }

  // Figures.
  h += "<section id=\"figures\">\n<h2>Figures</h2>\n<table id=\"figures-table\">\n<tr><th>run"
       "</th><th>matrix</th><th>queries</th><th>positive</th><th>unanswered</th><th>AUC</th>"
       "<th>R@100P</th><th>max F1</th><th>at threshold</th><th>precision</th><th>recall</th>"
       "<th>R@1</th><th>R@5</th><th>R@10</th><th>ABLE-P AP %</th></tr>\n";
  for (const EvaluatedRun& run : evaluation.runs) {
    const PerQueryResult& p = run.per_query;
    h += "<tr><td>" + Escape(run.label + (run.verified ? " (verified)" : "")) + "</td><td>" +
         Escape(run.source) + "</td><td class=\"n\">" + std::to_string(p.queries) +
         "</td><td class=\"n\">" + std::to_string(p.positive_queries) + "</td><td class=\"n\">" +
         std::to_string(p.unanswered) + "</td>";
    for (const double v : {p.auc, p.recall_at_100p, p.max_f1, p.max_f1_threshold,
                           p.max_f1_precision, p.max_f1_recall, p.recall_at_1, p.recall_at_5,
                           p.recall_at_10})
      h += "<td class=\"n\">" + Number(v, 4) + "</td>";
    h += "<td class=\"n\">" + Number(run.able_p.average_precision, 2) + "</td></tr>\n";
  }
  h += "</table>\n<p class=\"note\">Per query, its best match: AUC of the precision-recall "
       "curve, recall at 100 % precision, the best F1 and its threshold; R@N, the share of "
       "queries with a true place whose N best candidates hold one. ABLE-P: average precision "
       "over the thresholded matrix's cells.</p>\n</section>\n";

  // Precision-recall figure.
  h += "<section id=\"pr\">\n<h2>Precision-recall</h2>\n<figure>" +
       PngImage(RenderEvaluationPr(evaluation), "figure", "precision-recall figure") +
       "</figure>\n</section>\n";

  // Matrices.
  h += "<section id=\"matrix\">\n<h2>Matrix and ground truth</h2>\n<p class=\"note\">The "
       "evaluated block: queries are rows, references columns, dark = small distance; the "
       "ground truth is tinted blue; each query's best match is marked green when correct, red "
       "when wrong, where it is accepted at the run's operating point.</p>\n";
  for (std::size_t i = 0; i < evaluation.runs.size(); ++i) {
    const EvaluatedRun& run = evaluation.runs[i];
    h += "<figure>" +
         PngImage(RenderRunOverlay(evaluation, i, *input.matrices[i]), "figure overlay",
                  "matrix of " + run.label + " with the ground truth") +
         "<figcaption>" + Escape(run.label) + ": " + std::to_string(run.layout.queries) +
         " queries x " + std::to_string(run.layout.references) +
         " references; answers marked at threshold " +
         Number(OperatingThreshold(run), 4) + "</figcaption></figure>\n";
  }
  h += "</section>\n";

  h += ExplorerSection(input);
  h += WorstCaseSections(input);

  // Every embedded image must decode: the console names any that did not (a damaged or
  // truncated page), and the page records the count (data-images-loaded) for tests.
  h += "<script>\nwindow.addEventListener('load', function () {\n"
       "  var images = document.images, loaded = 0;\n"
       "  for (var i = 0; i < images.length; ++i) {\n"
       "    if (images[i].complete && images[i].naturalWidth > 0) ++loaded;\n"
       "    else console.error('OpenABLE report: image not decoded: ' + images[i].alt);\n"
       "  }\n"
       "  document.body.setAttribute('data-images-loaded', loaded + '/' + images.length);\n"
       "});\n</script>\n</body>\n</html>\n";
  return h;
}

}  // namespace openable
