// The HTML report of an evaluation (Report_name, openable_evaluate --report): one
// self-contained page a person opens in a browser, offline: every image is embedded as a data
// URI, no script or style sheet is fetched. It shows the settings, the figures of each run,
// the precision-recall figure, the matrix with the ground truth drawn over it, and for each
// run the frames of its worst cases side by side, as VPR_Tutorial shows them, and an
// interactive explorer of each run (html_explorer.h):
//
//   most confident wrong matches  answered queries whose best match is wrong, most confident
//                                 (lowest score) first: query, wrong match, true place
//   misses                        queries with a true place that the run does not get right at
//                                 its operating point (Match_threshold, else the max-F1
//                                 threshold): unanswered, wrong, or right but not accepted;
//                                 least confident first: query, best match, true place
//
// The true place shown is the query's ground-truth candidate with the smallest distance in
// the matrix. A short script at the end of the page checks that every embedded image decoded
// and says which did not in the browser's console (docs/output_formats.md, "HTML report").
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

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

struct ReportInput {
  std::string program;  // "Test_OpenABLE" or "openable_evaluate"
  std::string title;    // heading of the page
  // Rows of the settings table (key, value), e.g. the keys that differ from the defaults.
  std::vector<std::pair<std::string, std::string>> settings;
  std::string all_settings;  // every key (FormatConfig), shown folded; empty: left out
  const Evaluation* evaluation = nullptr;
  std::vector<const cv::Mat1f*> matrices;  // the normalised matrix of each run
  int examples = 6;                        // Report_examples
  ReportFrames frames;
  std::vector<ReportTable> tables;         // shown after the settings
};

// The page. Throws InputError naming the frame when a frame of a worst case cannot be read.
std::string EncodeHtmlReport(const ReportInput& input);

// The keys of `config` whose value differs from the default, as (key, value) pairs in the
// order of the configuration reference.
std::vector<std::pair<std::string, std::string>> ChangedSettings(const Config& config);

}  // namespace openable
