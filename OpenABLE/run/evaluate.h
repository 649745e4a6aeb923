// Evaluation of a run (Test_OpenABLE with Ground_truth_type set) or of saved matrices
// (openable_evaluate); its files are written by OpenABLE/reports/evaluation_files.h. The protocols
// themselves are in OpenABLE/evaluation/ (docs/evaluation.md).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/metrics.h"
#include "OpenABLE/evaluation/report.h"
#include "config/config.h"

namespace openable {

// Every evaluated matrix of one evaluation, with the ground truth of each.
struct Evaluation {
  EvaluationSettings settings;
  std::vector<EvaluatedRun> runs;
  std::vector<GroundTruth> truths;  // truths[i] belongs to runs[i]
  // rejected[i]: cells (x = reference column, y = query row of the block) of the candidates
  // geometric verification rejected in runs[i]; empty without verification.
  std::vector<std::vector<cv::Point>> rejected;
};

// What geometric verification gives the evaluation of a run.
struct VerifiedAnswers {
  std::vector<std::vector<Answer>> accepted;  // per query of the layout, best first
  std::vector<cv::Point> rejected;            // candidates rejected, as Evaluation::rejected
};

// True when Ground_truth_type is set.
bool EvaluationRequested(const Config& config);

// The evaluation keys of `config` as option structs (Ground_truth_min_gap -1 = Exclusion),
// checked (InputError naming the key).
EvaluationSettings EvaluationSettingsFrom(const Config& config);

// "LDB L=10", or Evaluation_label when set.
std::string RunLabel(const Config& config);

// Loads the ground truth for `layout` (a block of `normalized`) and evaluates `normalized` with
// both protocols; appends the result to `evaluation`. With `verified` (the accepted candidates
// of geometric verification per query of the layout, best first), the run's
// per-query figures are those of the verified answers (EvaluateAnswers) and the matrix's best
// matches go to per_query_unverified. Throws InputError on bad ground truth.
void EvaluateMatrix(Evaluation& evaluation, const cv::Mat1f& normalized,
                    const EvaluationLayout& layout, const std::string& label,
                    const std::string& source, const VerifiedAnswers* verified = nullptr);

// The run's operating point: Match_threshold when set, else the max-F1 threshold.
double OperatingThreshold(const EvaluatedRun& run);

// The checks of a distance matrix before it is evaluated, shared by openable_evaluate
// (EvaluateMatrixFiles) and Python's evaluate: not empty; every cell >= 0, or a cell without a
// value (NaN, as Test_OpenABLE's .npy writes it, or +inf, as it is held in memory), which is
// never a candidate. Returns `matrix` itself, or a copy with NaN made +inf when it holds NaN.
// Throws InputError "<what> holds -1 at row 3, column 7; expected distances >= 0 ...".
cv::Mat1f DistancesForEvaluation(const cv::Mat1f& matrix, const std::string& what);

// A saved matrix to evaluate (openable_evaluate's --matrix and --label).
struct MatrixFile {
  std::string path;
  std::string label;  // legend label; empty: the file name without its extension
};

// Reads each matrix (ReadMatrixFile: .npy, text or image), checks it (DistancesForEvaluation),
// normalises it by its maximum (Eq. 5; no change for Test_OpenABLE's M'), takes its
// layout (not square: queries x references; square: two traversals of which the first
// `reference_frames` frames are the reference when reference_frames > 0, queries x references
// with `query_reference`, else one sequence) and evaluates it into `evaluation`
// (EvaluateMatrix). Returns the normalised matrices in the order of `files`. Throws InputError
// naming the file.
std::vector<cv::Mat1f> EvaluateMatrixFiles(Evaluation& evaluation,
                                           const std::vector<MatrixFile>& files,
                                           int reference_frames, bool query_reference = false);

}  // namespace openable
