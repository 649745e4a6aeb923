// Text forms of an evaluation: the curves as CSV, the figures and settings as JSON, and the
// short table printed at the end of a run.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/metrics.h"

namespace openable {

// One evaluated matrix.
struct EvaluatedRun {
  std::string label;   // legend label ("LDB L=10")
  std::string source;  // where the matrix came from (a file, or "Test_OpenABLE run")
  EvaluationLayout layout;
  std::int64_t truth_pairs = 0;      // ground-truth pairs loaded over the block
  std::int64_t truth_dropped = 0;    // GroundTruth::dropped
  std::string truth_skipped_header;  // GroundTruth::skipped_header
  // The run's final answers: with verification (`verified`), each query's best-ranked verified
  // candidate (a query without one has no answer), and per_query_unverified the matrix's best
  // matches; without verification, per_query holds the matrix's best matches.
  bool verified = false;
  PerQueryResult per_query;
  PerQueryResult per_query_unverified;
  AblePResult able_p;
  // The matrix (never the verified answers) under each reference protocol Evaluation_protocol
  // names (protocols.h), in the table's order.
  std::vector<ProtocolFigures> reference;
  // What makes the figures say little about the matrix, one line each (EvaluationWarnings, on
  // the matrix's own answers): printed by the programs on stderr and under the table.
  std::vector<std::string> warnings;
};

// The settings every run of one evaluation shares.
struct EvaluationSettings {
  GroundTruthOptions truth;
  EvaluationOptions options;
};

// "threshold,precision,recall,f1,tp,fp" then one line per point, 9 significant digits.
std::string EncodeCurveCsv(const std::vector<CurvePoint>& curve);

// A number of the CSV files: 9 significant digits (FormatNumber), "null" when it is not finite.
std::string CsvNumber(double value);

// A JSON object: {"openable_version", "settings": {ground truth, tolerance, exclusion, vicinity,
// match_score, match_score_window, able_thresholds}, "runs": [{"label", "source",
// "layout": {...}, "ground_truth": {...}, "verified", "per_query": {auc, recall_at_100p, max_f1,
// max_f1_threshold, max_f1_precision, max_f1_recall, recall_at_1, recall_at_5, recall_at_10,
// queries, positive_queries, unanswered_queries, accepted (at Match_threshold, when set),
// truth_pairs_outside_candidates}, "per_query_unverified" (the same, when verified),
// "able_p": {average_precision_percent, candidate_cells,
// truth_cells}}]}. Numbers with 9 significant digits, null when not finite
// (io/json.h, docs/output_formats.md). EncodeEvaluationJson is its text (json::Dump).
nlohmann::ordered_json EvaluationJson(const EvaluationSettings& settings,
                                      const std::vector<EvaluatedRun>& runs,
                                      const std::string& version);
std::string EncodeEvaluationJson(const EvaluationSettings& settings,
                                 const std::vector<EvaluatedRun>& runs, const std::string& version);

// The pieces of that JSON, for documents that hold evaluated runs among other things
// (openable_sweep): the "settings" object, and the members of one run object, added to `object`
// after those it holds.
nlohmann::ordered_json EvaluationSettingsJson(const EvaluationSettings& settings);
void AddEvaluatedRunJson(nlohmann::ordered_json& object, const EvaluatedRun& run);

// One row of the table of each run under each protocol chosen (FormatEvaluationTable's "By
// protocol", the HTML report's figures): the run's label, the protocol, its AUC, R@100P and
// R@1/5/10 as that protocol defines them (NaN where it leaves one undefined) and a few more
// figures as text. Rows only when Evaluation_protocol names a reference protocol: per run, the
// toolbox's own first (when chosen), then each reference protocol in the order of their table
// (protocols.h).
struct ProtocolRow {
  std::string label, protocol;
  double auc = 0, recall_at_100p = 0, recall_at_1 = 0, recall_at_5 = 0, recall_at_10 = 0;
  std::string more;
};
std::vector<ProtocolRow> ProtocolRows(const EvaluationSettings& settings,
                                      const std::vector<EvaluatedRun>& runs);
// The note under those rows when Tolerance widens the true references of a reference
// protocol's own ground-truth file; empty otherwise.
std::string ProtocolToleranceNote(const EvaluationSettings& settings);

// A few lines for a terminal: the protocol settings, then one row per run with AUC, R@100P,
// max F1 (threshold), R@1/5/10 and ABLE-P AP, the operating point (Match_threshold: answers
// accepted, right, precision, recall); with a reference protocol (protocols.h), a
// table of each run under each protocol chosen (AUC, R@100P, R@1/5/10 as each defines them);
// last, each run's warnings ("  warning: ..."). Text that is not valid UTF-8 (the ground
// truth's path, a label) is shown by ToValidUtf8.
std::string FormatEvaluationTable(const EvaluationSettings& settings,
                                  const std::vector<EvaluatedRun>& runs);

}  // namespace openable
