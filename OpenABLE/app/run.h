// A run of Test_OpenABLE from its configuration to its files, as one call: the program is a
// thin layer over Run and FormatRunReport.
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/run/evaluate.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/run/verify.h"
#include "OpenABLE/tuning/auto.h"
#include "config/config.h"

namespace openable {

struct RunOutcome {
  RunResult result;
  // Auto 1: the candidates, their criteria and the choice; `config` there is the configuration
  // the run went on with.
  std::unique_ptr<AutoChoice> automatic;
  std::unique_ptr<RunVerification> verification;  // when Verification is 1
  std::unique_ptr<Evaluation> evaluation;         // when Ground_truth_type is set (not bounded)
  std::vector<std::string> written;               // the paths of the outputs
};

// Checks the evaluation settings, chooses the settings from the data when Auto is 1
// (ChooseSettings, auto.h: the run then goes on with the chosen configuration, from the
// single-frame matrices the choice computed; an untrusted choice accepts no match), computes
// the run (ComputeRun), verifies its candidates when Verification is 1 (VerifyRun), evaluates
// its matrix (and the verified answers) when Ground_truth_type is set, and writes the outputs
// (WriteOutputs). `log` receives, as they
// arise, lines "warning: ..." (a problem that only costs time or a feature unavailable here)
// and "note: ..." (an output or evaluation this mode cannot give). Throws InputError naming
// the key, file or value.
RunOutcome Run(const Config& config, ProgressReporter& progress,
               const std::function<void(const std::string&)>& log);

// The report Test_OpenABLE prints at the end: descriptor and camera, traversals, mode and
// matrix, the auto mode's candidates and choice, timings, the evaluation table, the files
// written. With Auto 1 the run is described by the chosen configuration, not `config`. Paths
// and names that are not valid UTF-8 are shown by ToValidUtf8 (base/strings.h), as in every
// text output.
std::string FormatRunReport(const Config& config, const RunOutcome& outcome);

// The same report as one JSON object (Test_OpenABLE --json), for scripts: {"program",
// "openable_version", "descriptors": [{name, row_width, metric}], "camera", "traversals":
// [{key, path, frames, first_row, frame_width, frame_height, skipped: [...]}], "mode",
// "bounded", "index" (Approximate_search: the engine used, else null), "matches_kept"
// (bounded) or "matrix": {rows, cols}, "max_distance", "empty_cells", "threshold_cells_below"
// (Threshold set, else null), "accepted": {queries, answered, match_threshold} or null,
// "verification": {queries, candidates_checked, geometric, answered, seconds} or null,
// "timings": {total, description, matching, sequences, evaluation, export (seconds), frames,
// pairs}, "evaluation" (EvaluationJson's object, or null), "auto" (AutoJson's object with
// Auto 1, else null), "notes", "written"}. Numbers as in the evaluation JSON (io/json.h,
// docs/output_formats.md).
std::string EncodeRunJson(const Config& config, const RunOutcome& outcome);

// The --json report of the other programs: {"program": `program`, "openable_version", then
// `members` in order (name, value), then "written": the paths}. One object, ending with a
// newline (json::Dump).
std::string ProgramJson(const std::string& program,
                        const std::vector<std::pair<std::string, nlohmann::ordered_json>>& members,
                        const std::vector<std::string>& written);

}  // namespace openable
