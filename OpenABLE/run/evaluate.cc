#include "OpenABLE/run/evaluate.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <limits>
#include <set>
#include <stdexcept>

#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "OpenABLE/evaluation/plots.h"
#include "matching/normalize.h"

namespace openable {
bool EvaluationRequested(const Config& config) { return config.evaluation.Requested(); }

EvaluationSettings EvaluationSettingsFrom(const Config& c) {
  EvaluationSettings s;
  s.truth = c.evaluation.truth;
  s.options = c.evaluation.protocol;
  // What the evaluation takes from the rest of the run: the frame number of row 0, whether
  // part of the source was selected, and the frame gap of loops (-1: the exclusion).
  s.truth.first_frame = c.input.initial_image;
  s.truth.range_selected = c.input.initial_image > 0 || c.input.final_image != -1;
  s.truth.min_frame_gap =
      c.evaluation.min_frame_gap >= 0 ? c.evaluation.min_frame_gap : s.options.exclusion;
  s.options.score = c.matching.score;
  s.options.score.window = c.matching.score.window;
  s.options.accept_threshold = c.matching.match_threshold;
  s.options.accept_consistency = c.matching.match_consistency;
  s.options.agreement = AgreementOf(c.matching);
  s.truth.Check();
  s.options.Check();
  return s;
}

std::string RunLabel(const Config& config) {
  if (!config.evaluation.label.empty()) return config.evaluation.label;
  // Rows given by a file are named by it (its name without ".npy").
  std::string label = config.descriptor.name;
  if (!config.input.descriptors_path.empty()) {
    label = std::filesystem::path(config.input.descriptors_path).stem().string();
    if (label.empty()) label = "NPY";
  }
  if (config.description.type == DescriptionType::kGrid)
    label += " " + std::to_string(config.description.grid_x) + "x" +
             std::to_string(config.description.grid_y);
  return label + " L=" + std::to_string(config.matching.sequence_length);
}

void EvaluateMatrix(Evaluation& evaluation, const cv::Mat1f& normalized,
                    const EvaluationLayout& layout, const std::string& label,
                    const std::string& source, const VerifiedAnswers* verified) {
  GroundTruth truth =
      LoadGroundTruth(evaluation.settings.truth, layout, normalized.rows, normalized.cols);
  EvaluatedRun run;
  run.label = label;
  run.source = source;
  run.layout = layout;
  run.truth_pairs = truth.PairCount();
  run.truth_dropped = truth.dropped;
  run.truth_skipped_header = truth.skipped_header;
  run.per_query = EvaluatePerQuery(normalized, layout, truth, evaluation.settings.options);
  run.warnings =
      EvaluationWarnings(normalized, layout, truth, evaluation.settings.options, run.per_query);
  if (verified != nullptr) {
    run.verified = true;
    run.per_query_unverified = std::move(run.per_query);
    // The operating point: Match_threshold when set, else every verified answer.
    EvaluationOptions options = evaluation.settings.options;
    if (options.accept_threshold < 0)
      options.accept_threshold = std::numeric_limits<double>::infinity();
    run.per_query = EvaluateAnswers(layout, truth, verified->accepted, options);
  }
  run.able_p = EvaluateAbleP(normalized, layout, truth, evaluation.settings.options);
  const EvaluationOptions& options = evaluation.settings.options;
  run.reference =
      EvaluateReferenceProtocols(normalized, layout, truth, options.protocols, options.tolerance);
  evaluation.runs.push_back(std::move(run));
  evaluation.truths.push_back(std::move(truth));
  evaluation.rejected.push_back(verified != nullptr ? verified->rejected
                                                    : std::vector<cv::Point>());
}

double OperatingThreshold(const EvaluatedRun& run) {
  return run.per_query.has_operating_point ? run.per_query.operating_point.threshold
                                           : run.per_query.max_f1_threshold;
}

cv::Mat1f DistancesForEvaluation(const cv::Mat1f& matrix, const std::string& what) {
  if (matrix.empty())
    throw InputError(what + " is empty (" + std::to_string(matrix.rows) + " x " +
                     std::to_string(matrix.cols) +
                     "); expected a distance matrix with at least "
                     "one query and one reference");
  // A plain loop: OpenCV's vectorised comparisons do not single out NaN. +inf is a cell without
  // a value (Sequence_partial: skip, or a diagonal too short for a sequence); NaN is damage,
  // never a value OpenABLE writes, so it is refused rather than read as a skipped cell.
  for (int i = 0; i < matrix.rows; ++i) {
    const float* row = matrix.ptr<float>(i);
    for (int j = 0; j < matrix.cols; ++j) {
      const float v = row[j];
      if (std::isnan(v))
        throw InputError(what + " holds NaN at row " + std::to_string(i) + ", column " +
                         std::to_string(j) +
                         ": a damaged matrix; expected distances >= 0, and "
                         "+inf for a cell without a value (matrices written by earlier OpenABLE "
                         "builds held NaN there: numpy.nan_to_num(m, nan=numpy.inf) converts "
                         "one)");
      if (!(v >= 0.0f))
        throw InputError(what + " holds " + FormatNumber(v) + " at row " + std::to_string(i) +
                         ", column " + std::to_string(j) +
                         "; expected distances >= 0 (+inf for a cell without a value)");
    }
  }
  return matrix;
}

std::vector<cv::Mat1f> EvaluateMatrixFiles(Evaluation& evaluation,
                                           const std::vector<MatrixFile>& files,
                                           int reference_frames, bool query_reference) {
  std::vector<cv::Mat1f> loaded;
  loaded.reserve(files.size());
  for (const MatrixFile& m : files) {
    cv::Mat1f matrix = ReadMatrixFile(m.path);
    matrix = DistancesForEvaluation(matrix, "matrix " + Quoted(m.path));
    NormalizeByMax(matrix);
    EvaluationLayout layout;
    if (matrix.rows != matrix.cols || query_reference) {
      layout = EvaluationLayout::QueryReference(matrix.rows, matrix.cols);
    } else if (reference_frames > 0) {
      if (reference_frames >= matrix.rows)
        throw InputError("--reference-frames: " + std::to_string(reference_frames) +
                         " leaves no query frame in the " + std::to_string(matrix.rows) + "x" +
                         std::to_string(matrix.cols) + " matrix " + Quoted(m.path) +
                         "; expected fewer frames than its rows");
      layout = EvaluationLayout::TwoTraversals(reference_frames, matrix.rows - reference_frames);
    } else {
      layout = EvaluationLayout::LoopClosure(matrix.rows);
    }
    const std::string label =
        m.label.empty() ? std::filesystem::path(m.path).stem().string() : m.label;
    EvaluateMatrix(evaluation, matrix, layout, label, m.path);
    loaded.push_back(std::move(matrix));
  }
  return loaded;
}

}  // namespace openable
