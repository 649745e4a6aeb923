// openable_sweep: every combination of a few keys' values, each run as Test_OpenABLE runs it,
// evaluated against the configuration's ground truth and ranked. A thin layer over
// openable::RunSweep (OpenABLE/tuning/sweep.h).
#include <iostream>
#include <string>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/app/command_line.h"
#include "OpenABLE/io/json.h"

namespace {

const char* kUsage =
    "Usage: openable_sweep Config.txt --vary Key=v1,v2,... [--vary ...] [--set Key=Value ...]\n"
    "                      [--output PREFIX] [--rank-by FIGURE] [--best N] [options]\n"
    "\n"
    "Runs every combination of the values given with --vary, each as Test_OpenABLE would run\n"
    "the configuration with those values set, evaluates each against the configuration's\n"
    "ground truth (Ground_truth_type and its keys, docs/evaluation.md), and ranks the runs.\n"
    "Without ground truth, --rank-by agreement ranks them by criteria of their matrices alone\n"
    "(how consistent and how distinct the best matches are; with ground truth both are shown,\n"
    "so you can see whether the criterion agrees with the figures).\n"
    "Frames are described once per description setting: runs that differ only in sequence\n"
    "length, score, contrast enhancement, fusion weights or threshold reuse the single-frame\n"
    "matrices. Writes the ranked table on stdout and PREFIX.csv, PREFIX.json and, with ground\n"
    "truth, PREFIX_pr.png (the precision-recall curves of the best runs), all or nothing.\n"
    "\n"
    "Options:\n"
    "  --vary Key=v1,v2  a key and its values (repeatable, one per key); values are separated\n"
    "                    by commas, or by semicolons when a value holds commas\n"
    "                    (--vary Fusion_weights=1,1;2,1). Image_descriptor values may fuse\n"
    "                    descriptors with '+' (HOG+LDB). Output, Scale, SNAPS and odometry\n"
    "                    keys cannot be varied.\n"
    "  --output PREFIX   where the files go (default: Evaluation_name of the configuration,\n"
    "                    else \"sweep\" in the current folder)\n"
    "  --rank-by FIGURE  auc (default), recall_at_100p, recall_at_1, max_f1 or\n"
    "                    average_precision (ABLE-P), which need ground truth; or agreement,\n"
    "                    consistency or distinctiveness, which do not (docs/evaluation.md)\n"
    "  --best N          runs drawn in the precision-recall figure (default 5)\n"
    "  --set Key=Value   override one key of Config.txt for every run (repeatable)\n"
    "  --quiet           no progress lines (errors and the table are still printed)\n"
    "  --json            print the table as one JSON object on stdout (PREFIX.json's content)\n"
    "  --print-config    print the base configuration in effect and exit\n"
    "  --help-markdown   print the key reference as Markdown\n"
    "  --version         print the version\n"
    "  -h, --help        this help\n"
    "\n"
    "Every combination is checked before the first frame is read. Exit status: 0 success,\n"
    "1 bad configuration, value or input data (nothing written), 2 bad command line,\n"
    "3 internal error, 128 + signal when interrupted.\n"
    "\n"
    "Example (the presets were chosen this way):\n"
    "  openable_sweep config/presets/across_conditions.txt --set Images_path=A \\\n"
    "      --set Images_path_2=B --set Ground_truth_type=aligned \\\n"
    "      --vary Image_descriptor=LDB,HOG,SIFT --vary Image_sequences=1,5,10,30 \\\n"
    "      --vary Match_score=distance,ratio --output results/sweep\n"
    "\n"
    "Configuration keys (Config.txt: one 'Key: value' per line, '#' comments):\n";

int ParseCount(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || value < 1)
    throw openable::InputError(option + ": " + openable::Quoted(text) +
                               " is not valid; expected an integer >= 1");
  return value;
}

}  // namespace

int main(int argc, char** argv) {
  openable::KeepFrameBuffersOnTheHeap();
  return openable::RunConfigProgram(
      argc, argv, "openable_sweep", kUsage, "OpenABLE " + std::string(openable::kVersion),
      [](const openable::Config& config, const openable::CommandLine& command_line,
         openable::ProgressReporter& progress) {
        openable::SweepOptions options;
        std::string prefix = config.evaluation.name.empty() ? "sweep" : config.evaluation.name;
        for (const auto& [option, value] : command_line.options) {
          if (option == "--vary") {
            options.axes.push_back(openable::ParseSweepAxis(value));
          } else if (option == "--output") {
            if (value.empty())
              throw openable::InputError("--output: empty; expected a path prefix");
            prefix = value;
          } else if (option == "--rank-by") {
            options.rank_by = openable::ParseEnum<openable::SweepRank>(value, "--rank-by");
          } else if (option == "--best") {
            options.best = ParseCount("--best", value);
          }
        }
        openable::CheckOutputPrefix("--output", prefix);
        const bool quiet = command_line.quiet;
        const auto log = [quiet](const std::string& line) {
          if (!quiet || line.rfind("run ", 0) != 0)
            std::cerr << "openable_sweep: " << line << "\n";
        };
        const openable::SweepResult result = openable::RunSweep(config, options, progress, log);
        const std::vector<std::string> written = openable::WriteSweep(prefix, result);
        if (command_line.json) {
          std::cout << openable::ProgramJson(
              "openable_sweep",
              {{"sweep", openable::SweepJson(result, openable::kVersion)}}, written);
          return 0;
        }
        std::cout << openable::FormatSweepTable(result) << "Wrote:\n";
        for (const std::string& path : written) std::cout << "  " << path << "\n";
        return 0;
      },
      {"--vary", "--output", "--rank-by", "--best"});
}
