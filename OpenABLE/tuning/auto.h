// The auto mode (Auto 1, config/presets/auto.txt): a run of two traversals chooses its
// description and matching settings from the data itself, with no ground truth. Every frame is
// described once per candidate descriptor (the sweep's SingleFrameStore), each candidate of
// Auto_candidates gets the query-reference block of its sequence matrix, and the candidate with
// the highest agreement (OpenABLE/evaluation/unsupervised.h) is chosen. The run then goes on
// exactly as a run with the chosen settings written into its configuration: the same outputs,
// evaluation and report, from the single-frame matrices already computed. When the chosen
// candidate's consistency is below Auto_min_consistency the choice is not trusted: the run
// still writes its outputs, says so, and accepts no match (docs/evaluation.md).
#pragma once

#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/evaluation/unsupervised.h"
#include "OpenABLE/reports/html_report.h"
#include "OpenABLE/run/pipeline.h"
#include "config/config.h"

namespace openable {

// One candidate: the keys it sets over the run's configuration, in the order written (a fused
// descriptor without Fusion_weights gets "Fusion_weights=1,...,1").
using AutoSettings = std::vector<std::pair<std::string, std::string>>;

// The candidates of Auto_candidates, in order: groups separated by '|', each the combinations
// of its axes (the last varying fastest), axes "Key=v1,v2" separated by spaces, values as
// openable_sweep's --vary takes them (';' separates values that hold commas). Throws
// InputError naming Auto_candidates: an empty text, group or value; an unknown key or a value
// its key refuses; a key that does not change the matrix a candidate is judged by (outputs,
// frames, scores and thresholds, evaluation, verification, SNAPS); Exclusion, a setting of runs
// of one traversal; a key given twice in a group; a candidate given twice.
std::vector<AutoSettings> ParseAutoCandidates(const std::string& text);

// The candidates of a run's auto mode: Auto_candidates, and with Model_path set (a network of
// the user's, descriptors/onnx.h) the group "Image_descriptor=ONNX Image_sequences=10,20,40"
// when Auto_candidates names no ONNX candidate of its own.
std::string AutoCandidatesOf(const Config& config);

// "Key=value Key=value": how the report and the JSON name a candidate.
std::string AutoSettingsText(const AutoSettings& settings);

// `config` with the settings of `candidate` applied (and Auto 0): the configuration of the run
// the candidate stands for. Throws InputError naming Auto_candidates.
Config AutoCandidateConfig(const Config& config, const AutoSettings& candidate);

struct AutoCandidate {
  AutoSettings settings;
  UnsupervisedFigures figures;  // without the per-query vectors
};

struct AutoChoice {
  std::vector<AutoCandidate> candidates;  // in the order of Auto_candidates
  int chosen = -1;                        // index of the chosen candidate
  bool reliable = false;                  // its consistency >= min_consistency
  double min_consistency = 0.5;
  Config config;         // the run's configuration with the chosen settings
  int descriptions = 0;  // single-frame matrices computed
  double seconds = 0;    // describing, matching and judging the candidates
};

// Checks what the auto mode needs before any frame is read: two traversals, a dense matrix on
// one process, every candidate's configuration (CheckRun). Throws InputError naming the key.
void CheckAuto(const Config& config);

// The candidates' settings (a fused descriptor without Fusion_weights gets equal weights) and
// the configuration each stands for, over `config`.
struct AutoPlan {
  std::vector<AutoSettings> settings;
  std::vector<Config> configs;
};
AutoPlan PlanCandidates(const Config& config, const std::vector<AutoSettings>& candidates);

// Judges every candidate of `plan` on the query-reference block of its matrix and chooses: the
// single-frame matrix of each of its descriptors comes from `store` (SingleFrameKey of its
// configuration; every frame of two traversals, the reference's rows first, the query's from
// starts[1], starts = {0, references, references + queries}), fused and enhanced as a run
// does, then summed along sequences and judged by UnsupervisedCriteria. Sets every field but
// `descriptions` and `seconds`. Used by the auto mode and by a map's tuning (the map's rows,
// OnlineDetector::Tune), so that both choose alike from the same frames.
AutoChoice JudgeCandidates(const AutoPlan& plan, double min_consistency,
                           const SingleFrameStore& store, const std::vector<int>& starts,
                           ProgressReporter& progress,
                           const std::function<void(const std::string&)>& log);

// Describes the frames once per candidate descriptor into `store`, judges every candidate and
// chooses (CheckAuto first). `log` receives one line per candidate ("auto: 3 of 15: HOG
// Image_sequences=20: consistency 0.912, ..."). Throws InputError as ComputeRun does.
AutoChoice ChooseSettings(const Config& config, ProgressReporter& progress, SingleFrameStore& store,
                          const std::function<void(const std::string&)>& log);

// The lines of the run report: the candidates with their criteria, ranked, and the choice, or
// the warning that none could be trusted.
std::string FormatAutoReport(const AutoChoice& choice);

// The candidates as a table of the HTML report (Report_name), ranked, the chosen in bold.
ReportTable AutoReportTable(const AutoChoice& choice);

// The "auto" object of the --json report and of docs/output_formats.md: {"chosen": "Key=value
// ...", "chosen_settings": {...}, "reliable", "criterion": "agreement", "min_consistency",
// "descriptions", "seconds", "candidates": [{"settings", "rank", "queries", "answered",
// "agreeing", "consistency", "distinctiveness", "agreement", "gap", "tolerance"}]}.
nlohmann::ordered_json AutoJson(const AutoChoice& choice);

}  // namespace openable
