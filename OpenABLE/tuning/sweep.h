// A sweep over settings (openable_sweep, openable.sweep): every combination of a few keys'
// values, each run as Test_OpenABLE would run it and evaluated against the same ground truth,
// ranked by one figure. Frames are described once per descriptor and description setting,
// before the first run, and read once per description setting for all its descriptors
// (ComputeSingleFramesTogether): runs that differ only in what acts after the single-frame
// matrix (sequences, scores, contrast, fusion weights, threshold) share it through a
// SingleFrameStore.
#pragma once

#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/evaluation/report.h"
#include "OpenABLE/evaluation/unsupervised.h"
#include "config/config.h"

namespace openable {

// One varied key and its values, in the order given.
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

// "Key=v1,v2,v3" (or "Key=v1;v2;v3" when a value holds commas, as Fusion_weights=1,1;2,1
// does). Throws InputError naming the text when it is not of that form, the key is unknown or
// cannot be varied (outputs, the bounded and approximate modes, SNAPS and odometry keys), or a
// value is empty, repeated or not valid for the key (the checks of --set).
SweepAxis ParseSweepAxis(const std::string& text);

// The figure runs are ranked by (higher is better): from the per-query protocol or ABLE-P
// (ground truth needed), or one of the criteria computed from each run's matrix alone
// (OpenABLE/evaluation/unsupervised.h: no ground truth needed).
enum class SweepRank {
  kAuc,
  kRecallAt100p,
  kRecallAt1,
  kMaxF1,
  kAveragePrecision,
  kDistinctiveness,
  kConsistency,
  kAgreement
};
OPENABLE_ENUM_NAMES(SweepRank, "auc", "recall_at_100p", "recall_at_1", "max_f1",
                    "average_precision", "distinctiveness", "consistency", "agreement")

// True for the criteria that need no ground truth.
inline bool Unsupervised(SweepRank rank) {
  return rank == SweepRank::kDistinctiveness || rank == SweepRank::kConsistency ||
         rank == SweepRank::kAgreement;
}

struct SweepOptions {
  std::vector<SweepAxis> axes;  // at least one; keys distinct
  SweepRank rank_by = SweepRank::kAuc;
  int best = 5;  // runs drawn in the precision-recall figure, >= 1
};

// One combination, as run and evaluated.
struct SweepRun {
  std::vector<std::string> values;   // one per axis, in the order of SweepOptions::axes
  std::string label;                 // "HOG L=30 Match_score=ratio"
  EvaluatedRun evaluation;           // with ground truth (SweepResult::evaluated)
  UnsupervisedFigures unsupervised;  // always (without the per-query vectors)
  double seconds = 0;                // wall time of the run and its evaluation
  bool described = false;            // described frames (false: took kept single-frame matrices)
};

struct SweepResult {
  std::vector<SweepAxis> axes;
  SweepRank rank_by = SweepRank::kAuc;
  int best = 5;
  bool evaluated = false;       // the configuration has ground truth: runs carry `evaluation`
  EvaluationSettings settings;  // of the base configuration (runs may vary evaluation keys)
  std::vector<SweepRun> runs;   // ranked: best first; ties keep the order of the combinations
  int descriptions = 0;         // single-frame matrices computed (frames described that often)
  int frame_reads = 0;          // times the frames were read and decoded: once per description
                                // setting, for all its descriptors
  double seconds = 0;           // wall time of the whole sweep
};

// The configuration of one combination: `base` with values[i] set for axes[i], its output
// keys cleared (a sweep writes only its own files), Matrix_mode dense. Throws InputError.
Config SweepRunConfig(const Config& base, const std::vector<SweepAxis>& axes,
                      const std::vector<std::string>& values);

// Checks every combination (CheckConfig, the evaluation keys) before any work, then runs them
// in order (the last axis varies fastest). Every run gets the criteria of unsupervised.h and,
// when the configuration has Ground_truth_type, its evaluation; ranking by a figure of the
// evaluation needs the ground truth. Refuses Matrix_mode 2 and Approximate_search 1 (no dense
// matrix to evaluate), Auto 1, and an unsupervised ranking of runs with fewer than two queries.
// Throws InputError naming the key and value. `log` receives "run 3 of 32: HOG L=10" before
// each run and each distinct warning or note of the runs ("warning: ...", "note: ..."); each
// run's stages go to `progress`.
SweepResult RunSweep(const Config& base, const SweepOptions& options, ProgressReporter& progress,
                     const std::function<void(const std::string&)>& log);

// The ranked table for a terminal: one row per run with its settings, its criteria without
// ground truth (consistency, distinctiveness, agreement) and, with ground truth, AUC, R@100P,
// max F1, R@1, R@5 and ABLE-P AP, and its rank by the other kind (by AUC when ranked by a
// criterion, by agreement when ranked by a figure), so the two can be compared; a line on how
// often frames were described. Text that is not valid UTF-8 is shown by ToValidUtf8.
std::string FormatSweepTable(const SweepResult& result);

// The same rows as CSV: rank, one column per varied key, label, the figures of the evaluation
// (empty without ground truth), queries, the criteria without ground truth, seconds.
std::string EncodeSweepCsv(const SweepResult& result);

// The whole sweep as JSON (docs/output_formats.md): varied keys, ranking, evaluation
// settings, and per run its rank, settings, seconds and the figures of the evaluation JSON.
// EncodeSweepJson is its text (json::Dump).
nlohmann::ordered_json SweepJson(const SweepResult& result, const std::string& version);
std::string EncodeSweepJson(const SweepResult& result, const std::string& version);

// Writes <prefix>.csv, <prefix>.json and, with ground truth, <prefix>_pr.png (the `best` first
// runs), all or nothing. Returns the paths written; throws InputError naming --output and the path.
std::vector<std::string> WriteSweep(const std::string& prefix, const SweepResult& result);

}  // namespace openable
