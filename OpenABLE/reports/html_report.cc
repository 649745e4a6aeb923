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
#include "OpenABLE/evaluation/plots.h"
#include "OpenABLE/evaluation/report.h"
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
    const int height = std::max(
        1, static_cast<int>(std::lround(image.rows * double(kThumbnailWidth) / image.cols)));
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

ReportAnswers AnswersForReport(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                               const std::string& label, const std::string& source,
                               const EvaluationOptions& options) {
  ReportAnswers r;
  r.label = label;
  r.source = source;
  r.layout = layout;
  r.score = options.score;
  r.exclusion = options.exclusion;
  r.threshold = options.accept_threshold;
  r.consistency = options.accept_consistency;
  r.untrusted = options.accept_none;
  r.answers = AnswersOfMatrix(matrix, layout, options);
  return r;
}

std::vector<ReportRun> ReportRuns(const ReportInput& input) {
  std::vector<ReportRun> runs;
  if (input.evaluation != nullptr) {
    const Evaluation& evaluation = *input.evaluation;
    if (input.matrices.size() != evaluation.runs.size())
      throw std::logic_error("EncodeHtmlReport: one matrix per run expected");
    const EvaluationOptions& options = evaluation.settings.options;
    for (std::size_t i = 0; i < evaluation.runs.size(); ++i) {
      const EvaluatedRun& e = evaluation.runs[i];
      const PerQueryResult& p = e.per_query;
      ReportRun r;
      r.label = e.label;
      r.source = e.source;
      r.layout = e.layout;
      r.matrix = input.matrices[i];
      r.score = options.score;
      r.exclusion = options.exclusion;
      r.answers.best = p.best;
      r.answers.distance = p.best_distance;
      r.answers.score = p.score;
      r.answers.queries = p.queries;
      r.answers.answered = p.queries - p.unanswered;
      // The threshold's verdict by the rule of the operating point (verified answers: every
      // one when Match_threshold is not set), the run's matches as the evaluation counted them.
      EvaluationOptions accept = options;
      if (e.verified && accept.accept_threshold < 0)
        accept.accept_threshold = std::numeric_limits<double>::infinity();
      std::vector<std::uint8_t> confirmed;
      AcceptAnswers(p.best, p.score, accept, r.answers.accepted, confirmed);
      r.answers.confirmed =
          p.has_operating_point ? p.accepted : std::vector<std::uint8_t>(p.best.size(), 0);
      r.has_operating_point = p.has_operating_point;
      r.threshold = OperatingThreshold(e);
      r.consistency = options.accept_consistency;
      r.untrusted = options.accept_none;
      r.verified = e.verified;
      r.evaluated = &e;
      r.truth = &evaluation.truths[i];
      runs.push_back(std::move(r));
    }
    return runs;
  }
  if (input.matrices.size() != input.answers.size())
    throw std::logic_error("EncodeHtmlReport: one matrix per run expected");
  for (std::size_t i = 0; i < input.answers.size(); ++i) {
    const ReportAnswers& a = input.answers[i];
    const EvaluationLayout& layout = a.layout;
    const cv::Mat1f& m = *input.matrices[i];
    const auto n = static_cast<std::size_t>(layout.queries);
    const QueryAnswers& q = a.answers;
    if (layout.queries <= 0 || layout.references <= 0 || layout.row_offset < 0 ||
        layout.col_offset < 0 || layout.row_offset + layout.queries > m.rows ||
        layout.col_offset + layout.references > m.cols)
      throw std::logic_error("EncodeHtmlReport: the layout of " + a.label +
                             " does not fit its matrix");
    if (q.best.size() != n || q.distance.size() != n || q.score.size() != n ||
        q.accepted.size() != n || q.confirmed.size() != n)
      throw std::logic_error("EncodeHtmlReport: the answers of " + a.label +
                             " are not one per query of its layout");
    for (const int b : q.best)
      if (b < -1 || b >= layout.references)
        throw std::logic_error("EncodeHtmlReport: an answer of " + a.label +
                               " is not a column of its layout");
    ReportRun r;
    r.label = a.label;
    r.source = a.source;
    r.layout = layout;
    r.matrix = &m;
    r.score = a.score;
    r.exclusion = a.exclusion;
    r.answers = q;
    r.has_operating_point = a.threshold >= 0;
    r.threshold = a.threshold;
    r.consistency = a.consistency;
    r.untrusted = a.untrusted;
    r.verified = a.verified;
    runs.push_back(std::move(r));
  }
  return runs;
}

namespace {

std::string FrameName(const ReportFrames& frames, Frame f) {
  if (frames.name) return frames.name(f.row, f.index);
  return std::string(f.row ? "row " : "column ") + std::to_string(f.index);
}

// The cell of a table of cases showing a frame: query `block_index` of `layout` (a row of the
// matrix) or reference `block_index` (a column), with its thumbnail when the frames can be
// read, its name and its index in the block; `what` in a note when block_index is -1.
std::string FrameCell(const ReportFrames& frames, const EvaluationLayout& layout, bool query,
                      int block_index, const std::string& what, const std::string& css) {
  if (block_index < 0) return "<td class=\"note\">" + what + "</td>";
  const Frame f = query ? Frame{true, layout.row_offset + block_index}
                        : Frame{false, layout.col_offset + block_index};
  std::string c = "<td class=\"" + css + "\">";
  if (frames.read)
    c += PngImage(Thumbnail(frames.read(f.row, f.index)), "frame", FrameName(frames, f));
  c += Escape(FrameName(frames, f)) + "<br>" + (query ? "query " : "reference ") +
       std::to_string(block_index) + "</td>";
  return c;
}

// A note that the frames are named, not shown, and why; empty when they are shown.
std::string NoImagesNote(const ReportFrames& frames) {
  return frames.read ? ""
                     : "<p class=\"note\">Frames are named, not shown: " + Escape(frames.missing) +
                           "</p>\n";
}

// The two sections of worst cases (most confident wrong matches, misses), one table per run,
// with the frames when the report can read them.
std::string WorstCaseSections(const ReportInput& input) {
  const Evaluation& evaluation = *input.evaluation;
  const int exclusion = evaluation.settings.options.exclusion;
  std::string h;
  const ReportFrames& frames = input.frames;
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
      std::string score = c.answer >= 0
                              ? "score " + Number(c.score, 4) + "<br>match: " + distance(c.answer)
                              : std::string("no answer");
      if (c.true_place >= 0) score += "<br>true place: " + distance(c.true_place);
      t += "<tr data-query=\"" + std::to_string(c.query) + "\"><td>" + std::to_string(k + 1) +
           "<br>" + score + "</td>" + FrameCell(frames, run.layout, true, c.query, "", "") +
           FrameCell(frames, run.layout, false, c.answer, "no answer",
                     c.correct ? "right" : "wrong") +
           FrameCell(frames, run.layout, false, c.true_place, "no true place among the candidates",
                     "right") +
           "</tr>\n";
    }
    return t + "</table>\n";
  };
  const std::string no_images = NoImagesNote(frames);
  // One section per kind of worst case, one table per run.
  const auto cases_section = [&](const std::string& id, const std::string& title,
                                 const std::string& note, const std::string& kind,
                                 const auto& select) {
    std::string section = "<section id=\"" + id + "\">\n<h2>" + title +
                          "</h2>\n<p class=\"note\">" + note + "</p>\n" + no_images;
    for (std::size_t i = 0; i < evaluation.runs.size(); ++i)
      section +=
          cases_table(evaluation.runs[i], *input.matrices[i],
                      select(evaluation.runs[i], evaluation.truths[i], *input.matrices[i]), kind);
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

// "ratio" or "distance".
std::string ScoreName(const MatchScoreOptions& score) { return EnumName(score.kind); }

// "by 1 independent query" / "by n independent queries".
std::string PartnersText(int n) {
  return "by " + std::to_string(n) + (n == 1 ? " independent query" : " independent queries");
}

// Why a run without ground truth accepted no match; empty when it accepted some.
std::string NoneAcceptedReason(const ReportRun& run) {
  if (run.answers.Confirmed() > 0) return "";
  if (run.answers.answered == 0)
    return run.verified ? "no candidate of any query passed geometric verification"
                        : "no query has a best match";
  if (run.untrusted)
    return "the auto mode could not trust any candidate's settings, so the run accepts none "
           "(UNRELIABLE)";
  if (!run.has_operating_point) return "Match_threshold is not set (-1), so the run accepts none";
  if (run.answers.Accepted() == 0)
    return "no best match has a score at or below Match_threshold " + FormatNumber(run.threshold);
  return "Match_consistency confirmed none of the " + std::to_string(run.answers.Accepted()) +
         " best matches within Match_threshold";
}

// The operating point of each run: queries, answered, accepted by the threshold, confirmed by
// Match_consistency and, with ground truth, right, precision and recall of the run's matches.
std::string OperatingPointTable(const std::vector<ReportRun>& runs, bool truth) {
  std::string h =
      "<table id=\"operating-point-table\">\n<tr><th>run</th><th>queries</th>"
      "<th>answered</th><th>score</th><th>Match_threshold</th>"
      "<th>accepted</th><th>Match_consistency</th><th>confirmed</th>";
  if (truth) h += "<th>right</th><th>precision</th><th>recall</th>";
  h += "</tr>\n";
  for (const ReportRun& run : runs) {
    const QueryAnswers& a = run.answers;
    const std::string dash = "&ndash;";
    const bool point = run.has_operating_point;
    const std::string threshold = !point ? std::string("none")
                                  : std::isfinite(run.threshold)
                                      ? FormatNumber(run.threshold)
                                      : std::string("every verified answer");
    h += "<tr" + std::string(run.untrusted ? " class=\"unreliable\"" : "") + "><td>" +
         Escape(run.label + (run.verified ? " (verified)" : "")) + "</td><td class=\"n\">" +
         std::to_string(a.queries) + "</td><td class=\"n\">" + std::to_string(a.answered) +
         "</td><td>" + ScoreName(run.score) + "</td><td class=\"n\">" + threshold +
         "</td><td class=\"n\">" + (point ? std::to_string(a.Accepted()) : dash) +
         "</td><td class=\"n\">" +
         (run.consistency > 0 ? std::to_string(run.consistency) : std::string("0")) +
         "</td><td class=\"n\">" + (point ? std::to_string(a.Confirmed()) : dash) + "</td>";
    if (truth) {
      const PerQueryResult& p = run.evaluated->per_query;
      if (p.has_operating_point && !run.untrusted) {
        const CurvePoint& o = p.operating_point;
        h += "<td class=\"n\">" + std::to_string(o.tp) + "</td><td class=\"n\">" +
             Number(o.precision, 4) + "</td><td class=\"n\">" + Number(o.recall, 4) + "</td>";
      } else {
        h += "<td class=\"n\">" + dash + "</td><td class=\"n\">" + dash + "</td><td class=\"n\">" +
             dash + "</td>";
      }
    }
    h += "</tr>\n";
  }
  return h + "</table>\n";
}

// One sentence per run: what it answered and accepted, in words.
std::string OperatingPointSentence(const ReportRun& run) {
  const QueryAnswers& a = run.answers;
  std::string s = run.label + ": " + std::to_string(a.answered) + " of " +
                  std::to_string(a.queries) + " queries answered" +
                  (run.verified ? " (a candidate that passed geometric verification)"
                                : " (a best match with a value)");
  if (run.untrusted)
    return s +
           "; UNRELIABLE: the auto mode could not trust any candidate's settings, so the "
           "run accepts no match. The explorer's slider shows what a threshold would "
           "accept; the frames below are the best matches, not accepted.";
  if (!run.has_operating_point)
    return s +
           "; Match_threshold is not set (-1), so the run accepts none. Set it to accept "
           "the best matches whose " +
           ScoreName(run.score) +
           " score is at or below it; the explorer's slider shows how many a threshold "
           "accepts.";
  s += "; " + std::to_string(a.Accepted()) +
       (std::isfinite(run.threshold)
            ? " accepted with " + ScoreName(run.score) +
                  " score <= " + FormatNumber(run.threshold) + " (Match_threshold)"
            : std::string(" accepted (every verified answer: Match_threshold is -1)"));
  if (run.consistency > 0)
    s += ", " + std::to_string(a.Confirmed()) + " of them confirmed " +
         PartnersText(run.consistency) + " (Match_consistency)";
  return s + ": the run's " + std::to_string(a.Confirmed()) +
         (a.Confirmed() == 1 ? " match." : " matches.");
}

// Section "accepted" of a page without ground truth: per run, the frames of its accepted
// matches side by side, the most confident and the least confident (or, when it accepted
// none, of its best matches, said so).
std::string AcceptedSection(const ReportInput& input, const std::vector<ReportRun>& runs) {
  const ReportFrames& frames = input.frames;
  const int n = std::max(0, input.examples);
  std::string h =
      "<section id=\"accepted\">\n<h2>Accepted matches</h2>\n<p class=\"note\">The best "
      "matches the run accepted, each query's frame beside the frame it was matched to: the " +
      std::to_string(n) + " most confident (lowest score) and the " + std::to_string(n) +
      " least confident (highest score, the nearest to being refused). Without ground truth "
      "these are what to check by eye: a query matched to another place among the most "
      "confident means the settings confuse places with confidence; among the least "
      "confident, that the threshold lets other places in.</p>\n" +
      NoImagesNote(frames);
  for (const ReportRun& run : runs) {
    const QueryAnswers& a = run.answers;
    h += "<h3>" + Escape(run.label) + "</h3>\n";
    std::vector<int> pool;
    for (int q = 0; q < static_cast<int>(a.best.size()); ++q)
      if (a.best[q] >= 0 && a.confirmed[q]) pool.push_back(q);
    const bool none = pool.empty();
    if (none) {
      for (int q = 0; q < static_cast<int>(a.best.size()); ++q)
        if (a.best[q] >= 0) pool.push_back(q);
      h += "<p class=\"note" + std::string(run.untrusted ? " unreliable" : "") +
           "\">No match accepted: " + Escape(NoneAcceptedReason(run)) +
           ". Shown instead: the most and the least confident best matches, none of them "
           "accepted.</p>\n";
    }
    if (pool.empty() || n == 0) {
      h += "<p class=\"note\">" +
           std::string(pool.empty() ? "No query has a best match."
                                    : "Report_examples is 0: no frames shown.") +
           "</p>\n";
      continue;
    }
    std::stable_sort(pool.begin(), pool.end(),
                     [&](int x, int y) { return a.score[x] < a.score[y]; });
    const std::size_t most = std::min(pool.size(), static_cast<std::size_t>(n));
    const std::vector<int> confident(pool.begin(), pool.begin() + static_cast<long>(most));
    // The least confident among the rest, least confident first.
    std::vector<int> doubtful;
    for (std::size_t k = pool.size(); k > most && doubtful.size() < most; --k)
      doubtful.push_back(pool[k - 1]);
    const auto table = [&](const std::vector<int>& queries, const std::string& kind,
                           const std::string& title) {
      std::string t = "<h4>" + title + "</h4>\n";
      if (queries.empty()) return t + "<p class=\"note\">None beyond those above.</p>\n";
      t += "<table class=\"cases\" data-kind=\"" + kind +
           "\">\n<tr><th>#</th><th>query</th><th>matched frame</th></tr>\n";
      for (std::size_t k = 0; k < queries.size(); ++k) {
        const int q = queries[k];
        t += "<tr data-query=\"" + std::to_string(q) + "\" data-reference=\"" +
             std::to_string(a.best[q]) + "\"><td>" + std::to_string(k + 1) + "<br>" +
             (run.score.kind == MatchScore::kRatio ? "ratio score " + Number(a.score[q], 4) + "<br>"
                                                   : std::string()) +
             "distance " + Number(a.distance[q], 4) + "</td>" +
             FrameCell(frames, run.layout, true, q, "", "") +
             FrameCell(frames, run.layout, false, a.best[q], "", "") + "</tr>\n";
      }
      return t + "</table>\n";
    };
    const std::string what = none ? "best matches" : "accepted matches";
    h += "<div class=\"cases-row\"><div>\n" +
         table(confident, "accepted-confident", "Most confident " + what) + "</div><div>\n" +
         table(doubtful, "accepted-doubtful", "Least confident " + what) + "</div></div>\n";
  }
  return h + "</section>\n";
}

// The protocol rows of the settings table.
std::vector<std::pair<std::string, std::string>> ProtocolSettings(
    const ReportInput& input, const std::vector<ReportRun>& runs) {
  const bool one_sequence =
      !runs.empty() && runs[0].layout.kind == EvaluationLayout::Kind::kLoopClosure;
  std::vector<std::pair<std::string, std::string>> rows;
  if (input.evaluation != nullptr) {
    const EvaluationSettings& s = input.evaluation->settings;
    rows = {{"ground truth", Escape(GroundTruthTypeName(s.truth.type) +
                                    (s.truth.path.empty() ? "" : " (" + s.truth.path + ")"))},
            {"tolerance", "&plusmn;" + std::to_string(s.options.tolerance) + " frames"},
            {"match score", ScoreName(s.options.score)},
            {"ABLE-P vicinity", std::to_string(s.options.vicinity) + " frames"}};
    if (one_sequence)
      rows.insert(rows.begin() + 2, {"exclusion", std::to_string(s.options.exclusion) + " frames"});
    return rows;
  }
  rows.push_back({"ground truth", "none (no answer is judged)"});
  if (runs.empty()) return rows;
  const ReportRun& r = runs[0];
  if (one_sequence) rows.push_back({"exclusion", std::to_string(r.exclusion) + " frames"});
  const ReportAnswers& a = input.answers[0];
  rows.push_back(
      {"match score", ScoreName(r.score) + (r.score.kind == MatchScore::kRatio
                                                ? " (rivals beyond &plusmn;" +
                                                      std::to_string(r.score.window) + " frames)"
                                                : std::string())});
  return rows;
}

}  // namespace

std::string EncodeHtmlReport(const ReportInput& input) {
  const std::vector<ReportRun> runs = ReportRuns(input);
  const bool truth = input.evaluation != nullptr;
  // Progress: the precision-recall figure, each run's matrix figure, the explorer's steps and
  // the frames of the last sections.
  const std::int64_t total =
      (truth ? 1 : 0) + static_cast<std::int64_t>(runs.size()) + ExplorerSteps(input, runs) + 1;
  std::int64_t done = 0;
  const auto step = [&] {
    if (input.on_progress) input.on_progress(++done, total);
  };
  if (input.on_progress) input.on_progress(0, total);

  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       "<meta name=\"generator\" content=\"OpenABLE " +
       std::string(kVersion) +
       "\">\n"
       "<title>" +
       Escape(input.title) +
       "</title>\n<style>\n"
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
       ".no-truth{background:#fff8e1;border:1px solid #e0b040;padding:.6em .9em;line-height:1.5}\n"
       ".unreliable{color:#b00000;font-weight:bold}\n"
       ".cases-row{display:flex;flex-wrap:wrap;gap:2em;align-items:flex-start}\n"
       ".cases-row table.cases img{width:200px}\n"
       "pre{background:#f7f7f7;padding:.5em;overflow:auto;font-size:.85em}\n"
       // The explorer (html_explorer.h).
       ".ex-controls{margin:.5em "
       "0;line-height:1.8}.ex-threshold{width:360px;vertical-align:middle}\n"
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
  if (!truth) {
    const std::string advice =
        !input.truth_advice.empty()
            ? input.truth_advice
            : "To get precision and recall, give the ground truth of these frames: "
              "Ground_truth_type and Ground_truth in the configuration (aligned when query "
              "frame i shows the place of reference frame i; docs/evaluation.md lists the "
              "formats), or evaluate the saved matrix (Npy_name) with openable_evaluate "
              "--matrix M.npy --gt-type TYPE.";
    h += "<p class=\"no-truth\" id=\"no-truth\"><b>No ground truth.</b> This page shows what "
         "the run answered and accepted, not whether the answers are right: without a ground "
         "truth there is no precision, recall or wrong match to count. " +
         Escape(advice) +
         " Until then, check the accepted matches by eye (section "
         "<a href=\"#accepted\">Accepted matches</a>).</p>\n";
  }
  std::string extra_links;
  for (const ReportTable& t : input.tables)
    extra_links += "<a href=\"#" + Escape(t.id) + "\">" + Escape(t.title) + "</a> &middot; ";
  h += "<nav><a href=\"#settings\">Settings</a> &middot; " + extra_links +
       (truth ? "<a href=\"#figures\">Figures</a> &middot; <a href=\"#pr\">Precision-recall</a>"
              : "<a href=\"#operating-point\">Operating point</a>") +
       " &middot; <a href=\"#matrix\">Matrix</a> &middot; <a href=\"#explore\">Explore</a> "
       "&middot; " +
       (truth ? "<a href=\"#wrong-matches\">Wrong matches</a> &middot; "
                "<a href=\"#misses\">Misses</a>"
              : "<a href=\"#accepted\">Accepted matches</a>") +
       "</nav>\n";

  // Settings.
  h += "<section id=\"settings\">\n<h2>Settings</h2>\n<table id=\"settings-table\">\n"
       "<tr><th>setting</th><th>value</th></tr>\n";
  for (const auto& [key, value] : ProtocolSettings(input, runs))
    h += "<tr><td>" + key + "</td><td>" + value + "</td></tr>\n";
  for (const auto& [key, value] : input.settings)
    h += "<tr><td><code>" + Escape(key) + "</code></td><td><code>" + Escape(value) +
         "</code></td></tr>\n";
  h += "</table>\n";
  if (!input.settings.empty() && !input.settings_note.empty())
    h += "<p class=\"note\">" + Escape(input.settings_note) + "</p>\n";
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

  if (truth) {
    const Evaluation& evaluation = *input.evaluation;
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
      for (const double v :
           {p.auc, p.recall_at_100p, p.max_f1, p.max_f1_threshold, p.max_f1_precision,
            p.max_f1_recall, p.recall_at_1, p.recall_at_5, p.recall_at_10})
        h += "<td class=\"n\">" + Number(v, 4) + "</td>";
      h += "<td class=\"n\">" + Number(run.able_p.average_precision, 2) + "</td></tr>\n";
    }
    h += "</table>\n<p class=\"note\">Per query, its best match: AUC of the precision-recall "
         "curve, recall at 100 % precision, the best F1 and its threshold; R@N, the share of "
         "queries with a true place whose N best candidates hold one. ABLE-P: average precision "
         "over the thresholded matrix's cells.</p>\n";
    // The run's own operating point (Match_threshold), as the text table's "accepted" line.
    if (std::any_of(runs.begin(), runs.end(),
                    [](const ReportRun& r) { return r.has_operating_point; })) {
      h += "<h3>Operating point</h3>\n" + OperatingPointTable(runs, true) +
           "<p class=\"note\">The run's own operating point: the best matches whose score is at "
           "or below Match_threshold are accepted, and with Match_consistency n only those that "
           "n independent queries confirm are kept (confirmed: the run's matches). Right, "
           "precision and recall are those of the run's matches.";
      if (std::any_of(runs.begin(), runs.end(), [](const ReportRun& r) { return r.untrusted; }))
        h += " <span class=\"unreliable\">UNRELIABLE: the auto mode found no setting consistent "
             "enough to trust, and the run accepts no match.</span>";
      h += "</p>\n";
    }
    // The reference protocols (Evaluation_protocol vpr_bench, vpr_tutorial), as the text
    // table's "By protocol".
    const std::vector<ProtocolRow> protocol_rows =
        ProtocolRows(evaluation.settings, evaluation.runs);
    if (!protocol_rows.empty()) {
      h += "<h3>By protocol</h3>\n<table id=\"protocols-table\">\n<tr><th>run</th><th>protocol"
           "</th><th>AUC</th><th>R@100P</th><th>R@1</th><th>R@5</th><th>R@10</th><th>more</th>"
           "</tr>\n";
      for (const ProtocolRow& r : protocol_rows) {
        h += "<tr data-protocol=\"" + r.protocol + "\"><td>" + Escape(r.label) + "</td><td>" +
             r.protocol + "</td>";
        for (const double v :
             {r.auc, r.recall_at_100p, r.recall_at_1, r.recall_at_5, r.recall_at_10})
          h += "<td class=\"n\">" + Number(v, 4) + "</td>";
        h += "<td>" + Escape(r.more) + "</td></tr>\n";
      }
      h += "</table>\n<p class=\"note\">Each protocol's figures of the matrix's best matches, as "
           "its own code computes them (docs/evaluation.md, \"Protocols of VPR-Bench and "
           "VPR_Tutorial\"); a dash where a protocol leaves a figure undefined.";
      const std::string widened = ProtocolToleranceNote(evaluation.settings);
      if (!widened.empty()) h += " " + Escape(widened) + ".";
      h += "</p>\n";
    }
    h += "</section>\n";

    // Precision-recall figure.
    h += "<section id=\"pr\">\n<h2>Precision-recall</h2>\n<figure>" +
         PngImage(RenderEvaluationPr(evaluation), "figure", "precision-recall figure") +
         "</figure>\n</section>\n";
    step();
  } else {
    h += "<section id=\"operating-point\">\n<h2>Operating point</h2>\n" +
         OperatingPointTable(runs, false);
    for (const ReportRun& run : runs)
      h += "<p class=\"" + std::string(run.untrusted ? "unreliable" : "note") + "\">" +
           Escape(OperatingPointSentence(run)) + "</p>\n";
    h += "</section>\n";
  }

  // Matrices.
  h += "<section id=\"matrix\">\n<h2>" +
       std::string(truth ? "Matrix and ground truth" : "Matrix and accepted matches") +
       "</h2>\n<p class=\"note\">" +
       (truth ? "The evaluated block: queries are rows, references columns, dark = small "
                "distance; the ground truth is tinted blue; each query's best match is marked "
                "green when correct, red when wrong, where it is accepted at the run's "
                "operating point."
              : "The block of queries (rows) against references (columns), dark = small "
                "distance; the best matches the run accepted are marked orange.") +
       "</p>\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const ReportRun& run = runs[i];
    const cv::Mat3b image = truth ? RenderRunOverlay(*input.evaluation, i, *run.matrix)
                                  : RenderAnswersOverlay(*run.matrix, run.layout, run.answers.best,
                                                         run.answers.confirmed);
    h += "<figure>" +
         PngImage(image, "figure overlay",
                  "matrix of " + run.label + (truth ? " with the ground truth" : "")) +
         "<figcaption>" + Escape(run.label) + ": " + std::to_string(run.layout.queries) +
         " queries x " + std::to_string(run.layout.references) + " references; " +
         (truth ? "answers marked at threshold " + Number(run.threshold, 4)
                : std::to_string(run.answers.Confirmed()) + " accepted matches marked") +
         "</figcaption></figure>\n";
    step();
  }
  h += "</section>\n";

  h += ExplorerSection(input, runs, step);
  h += truth ? WorstCaseSections(input) : AcceptedSection(input, runs);
  step();

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
