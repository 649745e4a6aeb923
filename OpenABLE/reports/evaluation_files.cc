#include "OpenABLE/reports/evaluation_files.h"

#include <iterator>
#include <set>
#include <stdexcept>

#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/evaluation/plots.h"
#include "OpenABLE/reports/figures.h"

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

cv::Mat3b RenderRunOverlay(const Evaluation& evaluation, std::size_t i, const cv::Mat1f& matrix) {
  const EvaluatedRun& run = evaluation.runs.at(i);
  return RenderOverlay(matrix, run.layout, evaluation.truths.at(i), run.per_query,
                       OperatingThreshold(run),
                       run.verified ? &evaluation.rejected.at(i) : nullptr);
}

cv::Mat3b RenderEvaluationPr(const Evaluation& evaluation) {
  const EvaluationSettings& s = evaluation.settings;
  std::vector<PrSeries> series;
  for (const EvaluatedRun& run : evaluation.runs) {
    // With verification: the matrix's answers (and its ABLE-P cells), then the verified ones.
    if (run.verified) {
      series.push_back(
          {run.label + " unverified", run.per_query_unverified.curve, run.able_p.curve});
      series.push_back({run.label + " verified", run.per_query.curve, {}});
    } else {
      series.push_back({run.label, run.per_query.curve, run.able_p.curve});
    }
  }
  std::string title = "Precision-recall, " + GroundTruthTypeName(s.truth.type) +
                      " ground truth, tolerance +-" + std::to_string(s.options.tolerance);
  if (!evaluation.runs.empty() &&
      evaluation.runs[0].layout.kind == EvaluationLayout::Kind::kLoopClosure)
    title += ", exclusion " + std::to_string(s.options.exclusion);
  return RenderPrPlot(series, title, s.options.vicinity);
}

void StageEvaluation(OutputBatch& batch, const std::string& key, const std::string& prefix,
                     const Evaluation& evaluation, const std::vector<const cv::Mat1f*>& matrices) {
  if (matrices.size() != evaluation.runs.size())
    throw std::logic_error("StageEvaluation: one matrix per run expected");
  const EvaluationSettings& s = evaluation.settings;
  static_assert(std::size(kEvaluationSetSuffixes) == 2 && std::size(kEvaluationRunSuffixes) == 3,
                "one suffix per file staged below");
  batch.Stage(key, prefix + kEvaluationSetSuffixes[0],
              EncodeEvaluationJson(s, evaluation.runs, kVersion));
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
    batch.Stage(key, stem + kEvaluationRunSuffixes[0], EncodeCurveCsv(run.per_query.curve));
    batch.Stage(key, stem + kEvaluationRunSuffixes[1], EncodeCurveCsv(run.able_p.curve));
    batch.Stage(key, stem + kEvaluationRunSuffixes[2],
                EncodePng(RenderRunOverlay(evaluation, i, *matrices[i])));
    for (const ProtocolFigures& f : run.reference)
      batch.Stage(key, stem + FindReferenceProtocol(f.protocol)->csv_suffix, f.csv);
  }
  batch.Stage(key, prefix + kEvaluationSetSuffixes[1], EncodePng(RenderEvaluationPr(evaluation)));
}

}  // namespace openable
