// The files of a run (docs/output_formats.md): the matrix as text, .npy and images, the
// matches, the loops, the evaluation and the HTML report, written all or nothing.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/run/result.h"
#include "config/config.h"

namespace openable {

struct Evaluation;       // OpenABLE/run/evaluate.h
struct RunVerification;  // OpenABLE/run/verify.h
struct AutoChoice;       // OpenABLE/tuning/auto.h

// Writes the outputs the configuration asks for (Txt_name, Npy_name, Png_name,
// Png_threshold_name, Matches_name, Loops_name when `verification` is given, the files of
// Evaluation_name when `evaluation` is given, and Report_name: the page of the evaluation, or
// without `evaluation` that of the run's answers; it lists the auto mode's candidates when
// `automatic` is given, whose untrusted choice accepts no match in the report and the matches
// file) all-or-nothing. Cells without a value (+inf, Sequence_partial skip) are written as the
// largest finite value in Txt_name and the PNG images and as +inf in Npy_name. With
// `progress`, a stage "report" while the report reads its frames and a stage "writing" over
// the outputs and the commit. Returns the paths written. Adds the time spent to
// result.timings.export_seconds. Throws InputError naming the key and path on failure.
std::vector<std::string> WriteOutputs(const Config& config, RunResult& result,
                                      const Evaluation* evaluation = nullptr,
                                      const RunVerification* verification = nullptr,
                                      const AutoChoice* automatic = nullptr,
                                      ProgressReporter* progress = nullptr);

// Every file a run of `config` may write, as (key, path), in the order WriteOutputs writes
// them: the matrix files, the images, the matches, the loops (Verification), the frame times
// and, when Ground_truth_type is set, the evaluation's files (StageEvaluation) and the report.
// Run checks them with CheckDistinctOutputs before any work.
//
// The kinds of output are entries of one registry (run_outputs.cc) that both this list and
// WriteOutputs read. To add one: its key in OutputOptions (config/run_options.h) and the option
// table (config/config.cc), its entry in the registry, and its section in
// docs/output_formats.md.
std::vector<std::pair<std::string, std::string>> PlannedOutputs(const Config& config);

// The notes of a bounded run for the files it does not write (those made from the dense
// matrix: Txt_name, Npy_name, the images), one per file asked for: "<key>: not written: ...".
std::vector<std::string> UnwrittenOutputNotes(const Config& config, const RunResult& result);

// The thresholded image's path: Png_threshold_name, or Png_name with "_thresholded" before
// its extension; empty when no threshold or no PNG is asked for.
std::string ThresholdPngPath(const Config& config);

}  // namespace openable
