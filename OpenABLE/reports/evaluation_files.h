// The files and figures of an evaluation (docs/output_formats.md): <prefix>.json, the
// precision-recall figure, and per run the curves as CSV and the ground truth drawn over the
// matrix.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/run/evaluate.h"

namespace openable {

// The suffixes of the evaluation's files: once per evaluation (<prefix>.json, <prefix>_pr.png)
// and once per run (<prefix>[_<label>]_per_query.csv, ...), in the order StageEvaluation
// stages them.
inline constexpr const char* kEvaluationSetSuffixes[] = {".json", "_pr.png"};
inline constexpr const char* kEvaluationRunSuffixes[] = {"_per_query.csv", "_ablep.csv",
                                                         "_overlay.png"};

// The figures of the evaluation's files, also shown by the HTML report (html_report.h): the
// precision-recall figure of every run (<prefix>_pr.png), and run `i`'s ground truth and
// answers over its matrix (<prefix>_overlay.png), answers marked at the run's operating point
// (Match_threshold, else the max-F1 threshold).
cv::Mat3b RenderEvaluationPr(const Evaluation& evaluation);
cv::Mat3b RenderRunOverlay(const Evaluation& evaluation, std::size_t i, const cv::Mat1f& matrix);

// Stages the evaluation's files under `prefix` into `batch` (key = the config key to name in
// errors): <prefix>.json, <prefix>_pr.png, and per run <prefix>[_<label>]_per_query.csv,
// <prefix>[_<label>]_ablep.csv and <prefix>[_<label>]_overlay.png (the label part only when
// there are several runs). matrices[i] is the normalised matrix of runs[i].
void StageEvaluation(OutputBatch& batch, const std::string& key, const std::string& prefix,
                     const Evaluation& evaluation, const std::vector<const cv::Mat1f*>& matrices);

}  // namespace openable
