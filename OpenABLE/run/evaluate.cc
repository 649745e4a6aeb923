#include "OpenABLE/run/evaluate.h"

#include <cctype>
#include <set>
#include <stdexcept>

#include "OpenABLE/base/version.h"
#include "OpenABLE/evaluation/plots.h"

namespace openable {
namespace {

// A label made safe for a file name: letters, digits, '-', '.', others as '_'.
std::string FileSafe(const std::string& label) {
  std::string out;
  for (const char ch : label) {
    const auto c = static_cast<unsigned char>(ch);
    out += (std::isalnum(c) || ch == '-' || ch == '.') ? ch : '_';
  }
  return out.empty() ? "run" : out;
}

}  // namespace

bool EvaluationRequested(const Config& config) { return !config.ground_truth_type.empty(); }

EvaluationSettings EvaluationSettingsFrom(const Config& c) {
  EvaluationSettings s;
  s.truth.type = ParseGroundTruthType(c.ground_truth_type);
  s.truth.path = c.ground_truth;
  s.truth.path_2 = c.ground_truth_2;
  s.truth.base = c.ground_truth_base;
  s.truth.first_frame = c.initial_image;
  s.truth.range_selected = c.initial_image > 0 || c.final_image != -1;
  s.truth.radius = c.ground_truth_radius;
  s.truth.heading_limit = c.ground_truth_heading;
  s.truth.min_frame_gap = c.ground_truth_min_gap >= 0 ? c.ground_truth_min_gap : c.exclusion;
  s.truth.axes = c.ground_truth_axes;
  s.options.tolerance = c.tolerance;
  s.options.exclusion = c.exclusion;
  s.options.vicinity = c.vicinity;
  s.truth.Check();
  s.options.Check();
  return s;
}

std::string RunLabel(const Config& config) {
  if (!config.evaluation_label.empty()) return config.evaluation_label;
  std::string label = config.image_descriptor;
  if (config.description_type == 1)
    label += " " + std::to_string(config.grid_x) + "x" + std::to_string(config.grid_y);
  return label + " L=" + std::to_string(config.image_sequences);
}

void EvaluateMatrix(Evaluation& evaluation, const cv::Mat1f& normalized,
                    const EvaluationLayout& layout, const std::string& label,
                    const std::string& source) {
  GroundTruth truth =
      LoadGroundTruth(evaluation.settings.truth, layout, normalized.rows, normalized.cols);
  EvaluatedRun run;
  run.label = label;
  run.source = source;
  run.layout = layout;
  run.truth_pairs = truth.PairCount();
  run.truth_dropped = truth.dropped;
  run.per_query = EvaluatePerQuery(normalized, layout, truth, evaluation.settings.options);
  run.able_p = EvaluateAbleP(normalized, layout, truth, evaluation.settings.options);
  evaluation.runs.push_back(std::move(run));
  evaluation.truths.push_back(std::move(truth));
}

void StageEvaluation(OutputBatch& batch, const std::string& key, const std::string& prefix,
                     const Evaluation& evaluation, const std::vector<const cv::Mat1f*>& matrices) {
  if (matrices.size() != evaluation.runs.size())
    throw std::logic_error("StageEvaluation: one matrix per run expected");
  const EvaluationSettings& s = evaluation.settings;
  batch.Stage(key, prefix + ".json", EncodeEvaluationJson(s, evaluation.runs, kVersion));

  std::vector<PrSeries> series;
  std::set<std::string> used;
  for (std::size_t i = 0; i < evaluation.runs.size(); ++i) {
    const EvaluatedRun& run = evaluation.runs[i];
    std::string stem = prefix;
    if (evaluation.runs.size() > 1) {
      std::string part = FileSafe(run.label);
      if (!used.insert(part).second) part += "_" + std::to_string(i + 1);
      used.insert(part);
      stem += "_" + part;
    }
    batch.Stage(key, stem + "_per_query.csv", EncodeCurveCsv(run.per_query.curve));
    batch.Stage(key, stem + "_ablep.csv", EncodeCurveCsv(run.able_p.curve));
    batch.Stage(key, stem + "_overlay.png",
                EncodePng(RenderOverlay(*matrices[i], run.layout, evaluation.truths[i],
                                        run.per_query, run.per_query.max_f1_threshold)));
    series.push_back({run.label, run.per_query.curve, run.able_p.curve});
  }
  std::string title = "Precision-recall, " + GroundTruthTypeName(s.truth.type) +
                      " ground truth, tolerance +-" + std::to_string(s.options.tolerance);
  if (!evaluation.runs.empty() &&
      evaluation.runs[0].layout.kind == EvaluationLayout::Kind::kLoopClosure)
    title += ", exclusion " + std::to_string(s.options.exclusion);
  batch.Stage(key, prefix + "_pr.png", EncodePng(RenderPrPlot(series, title, s.options.vicinity)));
}

}  // namespace openable
