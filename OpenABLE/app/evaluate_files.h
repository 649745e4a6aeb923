// openable_evaluate as library calls: its command line (--matrix, --label, the flags that stand
// for evaluation keys, --config, --set), the evaluation of saved matrices with the keys of
// Config.txt (docs/evaluation.md), and its files: Evaluation_name's and the HTML report, whose
// worst cases show the frames when --images (--images-2) or --video says where they are.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/run/evaluate.h"
#include "config/config.h"

namespace openable {

struct EvaluateCommandLine {
  std::vector<MatrixFile> matrices;    // --matrix, each with the --label after it
  std::vector<std::string> overrides;  // "Key=Value" of the flags and of --set, in order
  std::string config_path;             // --config
  int reference_frames = 0;            // --reference-frames
  bool query_reference = false;        // --layout query_reference: square, yet queries x references
  bool quiet = false, json = false, help = false, version = false;
  bool help_keys = false;  // --help-keys [GROUP]
  std::string help_group;
};

// Parses argv. Returns an empty string, or one line ("openable_evaluate: ... (see --help)")
// naming the bad argument: an unknown option, a missing value, --label before any --matrix, a
// bad --reference-frames or --layout, or no --matrix. --help, --help-keys and --version end the
// parsing (answered whatever follows, as before any other argument is read).
std::string ParseEvaluateCommandLine(int argc, const char* const* argv, EvaluateCommandLine& out);

// The configuration of the command line, checked, and each matrix evaluated
// (EvaluateMatrixFiles). A matrix with a settings file (m.npy.json, matrix_settings.h) is
// evaluated with its run's evaluation settings and reference frames, under those of
// --config and the command line; matrices whose files disagree on a setting the command line
// does not give are refused. Throws InputError naming the key or file.
struct EvaluatedFiles {
  Config config;
  Evaluation evaluation;
  std::vector<cv::Mat1f> matrices;  // normalised, in the order of the command line
  // Where the settings came from when a matrix has a settings file (matrix_settings.h), and
  // each of its settings this evaluation changed: one line each, for stderr.
  std::vector<std::string> notes;
};
EvaluatedFiles EvaluateFiles(const EvaluateCommandLine& command_line);

// Writes Evaluation_name's files and Report_name, all or nothing; returns the paths written.
std::vector<std::string> WriteEvaluatedFiles(const EvaluatedFiles& evaluated,
                                             const std::vector<MatrixFile>& files);

}  // namespace openable
