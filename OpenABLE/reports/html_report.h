// The HTML report of a run or an evaluation (Report_name, openable_evaluate --report): one
// self-contained page a person opens in a browser, offline (every image a data URI, nothing
// fetched). With ground truth it shows the settings, figures, precision-recall curve, matrix,
// explorer (html_explorer.h) and each run's worst cases, as VPR_Tutorial shows them; without,
// it says nothing can be judged and shows the operating point and the most and least confident
// accepted matches to check by eye. Sections: docs/output_formats.md, "Report_name".
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/evaluation/answers.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/run/evaluate.h"

namespace openable {

// One worst case of a run, in block coordinates of its layout (docs/evaluation.md).
struct ReportCase {
  int query = -1;       // query row of the block
  int answer = -1;      // best match (block column), -1 when the query has no answer
  int true_place = -1;  // ground-truth candidate with the smallest distance, -1 when none
  float score = 0;      // the score of the answer (Match_score), +inf without an answer
  bool correct = false;
};

// The most confident wrong matches of `run` (at most `n`): queries with an answer that is not
// correct, by increasing score (ties: lower query first).
std::vector<ReportCase> ConfidentWrongMatches(const EvaluatedRun& run, const GroundTruth& truth,
                                              const cv::Mat1f& matrix, int exclusion, int n);

// The misses of `run` at `threshold` (at most `n`): positive queries whose answer is missing,
// wrong, or has a score above `threshold`; unanswered first, then by decreasing score (ties:
// lower query first).
std::vector<ReportCase> Misses(const EvaluatedRun& run, const GroundTruth& truth,
                               const cv::Mat1f& matrix, int exclusion, double threshold, int n);

// Where the report gets the images of frames. `row` tells whether `index` is a row or a column
// of the full matrix (they differ for a queries x references matrix of openable_evaluate).
struct ReportFrames {
  // The frame, as FrameSource::Read gives it (CV_32FC1 or CV_32FC3 in [0, 1]); unset: the
  // report names the frames without showing them, and says why (`missing`).
  std::function<cv::Mat(bool row, int index)> read;
  // A short name of the frame (its file name); unset: "row 12" / "column 40".
  std::function<std::string(bool row, int index)> name;
  std::string missing;  // why no images are shown (when `read` is unset)
  // Row i and column i of the matrix are the same frame (one sequence): the explorer embeds
  // the thumbnails once.
  bool same_rows_and_columns = false;
};

// ReportFrames over the frame sources of a run (OpenFramesToShow, pipeline.h): row and column
// i of the matrix are frame i of the sources taken one after the other, or, with
// `rows_are_second` (a queries x references matrix of two traversals), rows are the frames of
// sources[1] and columns those of sources[0]. Named by file name (FrameSource::FrameName).
ReportFrames FramesFromSources(std::vector<std::unique_ptr<FrameSource>> sources,
                               bool rows_are_second);

// A table of its own on the page, after the settings (the auto mode's candidates).
struct ReportTable {
  std::string id, title;                       // HTML id and heading
  std::string note;                            // a sentence under the table; may be empty
  std::vector<std::string> header;             // column titles
  std::vector<std::vector<std::string>> rows;  // cells, as text (escaped by the report)
  std::vector<bool> numeric;                   // per column: right-aligned numbers
  int highlight = -1;                          // a row shown in bold, -1 none
};

// One run shown without ground truth: what its matrix answered and what its operating point
// accepted, nothing judged right or wrong. For a matrix of Q queries (rows) against R
// references (columns) taken whole: layout = EvaluationLayout::QueryReference(Q, R), and
// answers with Q entries per query (best: a column 0 .. R-1, or -1). AnswersForReport fills
// it from a matrix; a program that finds its answers otherwise fills `answers` itself.
struct ReportAnswers {
  std::string label;        // the run's name, e.g. "HOG L=10"
  std::string source;       // where the matrix came from, e.g. "Test_OpenABLE run"
  EvaluationLayout layout;  // the block of the matrix shown: rows queries, columns references
  MatchScoreOptions score;  // what the scores are (Match_score; the window is shown only)
  int exclusion = 100;      // one sequence (Kind::kLoopClosure): candidates this far back
  double threshold = -1;    // Match_threshold: answers with a score <= it accepted; -1 none
  int consistency = 0;      // Match_consistency n: confirmed by n independent queries; 0 none
  bool untrusted = false;   // the auto mode could not trust its choice: nothing accepted
  bool verified = false;    // the answers are geometric verification's (Verification 1)
  // Per query row of the layout: best, distance, score, accepted, confirmed (answers.h;
  // confirmed = the run's matches, equal to accepted without Match_consistency).
  QueryAnswers answers;
};

// ReportAnswers of the block `layout` of `matrix` (normalised), scored and accepted as
// `options` says (AnswersOfMatrix: Match_score, Match_score_window, Exclusion,
// Match_threshold, Match_consistency with its agreement, accept_none; EvaluationSettingsFrom
// gives them from a Config), labelled `label` and `source`.
ReportAnswers AnswersForReport(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                               const std::string& label, const std::string& source,
                               const EvaluationOptions& options);

struct ReportInput {
  std::string program;  // "Test_OpenABLE" or "openable_evaluate"
  std::string title;    // heading of the page
  // Rows of the settings table (key, value), e.g. the keys that differ from the defaults.
  std::vector<std::pair<std::string, std::string>> settings;
  // The sentence under the settings table (when it has rows).
  std::string settings_note =
      "Keys of Config.txt shown above: those that differ from the defaults.";
  std::string all_settings;  // every key (FormatConfig), shown folded; empty: left out
  // With ground truth: the evaluation, one run per matrix. Null: the page is made from
  // `answers`, without ground truth.
  const Evaluation* evaluation = nullptr;
  // Without ground truth (evaluation null): the runs, one per matrix.
  std::vector<ReportAnswers> answers;
  // Without ground truth: what the reader can do to get precision and recall, as text (the
  // page escapes it); empty: a sentence naming Ground_truth_type, Ground_truth and
  // openable_evaluate.
  std::string truth_advice;
  // The normalised matrix of each run (evaluation->runs[i], or answers[i]); the block of the
  // run's layout is shown.
  std::vector<const cv::Mat1f*> matrices;
  int examples = 6;  // Report_examples
  ReportFrames frames;
  std::vector<ReportTable> tables;  // shown after the settings
  // Called as the page is made (done, total steps; first with done 0): a step per frame the
  // explorer reads for its thumbnails, the long part of a page of many frames, and one per
  // figure and section. For a progress line; unset: not called.
  std::function<void(std::int64_t done, std::int64_t total)> on_progress;
};

// The page, with ground truth when input.evaluation is set, else without. Throws InputError
// naming the frame when a frame it shows cannot be read, std::logic_error when there is not one
// matrix per run (or, without ground truth, a run's answers do not fit its layout).
//
// A page without ground truth for a Q x R block `m` (queries x references, normalised):
//   ReportInput input;
//   input.program = "openable_map";
//   input.title = "...";
//   input.settings = {{"map", "..."}};
//   input.answers = {AnswersForReport(m, EvaluationLayout::QueryReference(Q, R), "label",
//                                     "source", options)};
//   input.matrices = {&m};
//   input.frames.read = ...;  // (row = true, q): query q; (row = false, c): reference c
//   std::string page = EncodeHtmlReport(input);
std::string EncodeHtmlReport(const ReportInput& input);

// The keys of `config` whose value differs from the default, as (key, value) pairs in the
// order of the configuration reference.
std::vector<std::pair<std::string, std::string>> ChangedSettings(const Config& config);

}  // namespace openable
