// openable_sweep: every combination of a few keys' values, each run as Test_OpenABLE runs it,
// evaluated against the configuration's ground truth and ranked. A thin layer over
// openable::RunSweep (OpenABLE/tuning/sweep.h).
#include <iostream>
#include <string>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/app/command_line.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/io/json.h"

namespace {

// A function, not a constant: the ground-truth formats come from their registry.
openable::ProgramHelp Help() {
  return {
      "Usage: openable_sweep Config.txt --vary Key=v1,v2,... [--vary ...] [--set Key=Value ...]\n"
      "                      [--output PREFIX] [--rank-by FIGURE] [--best N] [options]\n"
      "\n"
      "Runs every combination of the --vary values as Test_OpenABLE would, evaluates each\n"
      "against the configuration's ground truth (docs/evaluation.md) and ranks them; without\n"
      "ground truth, --rank-by agreement ranks them by their matrices alone. Frames are described\n"
      "once per description setting. Writes the table on stdout and PREFIX.csv, PREFIX.json and,\n"
      "with ground truth, PREFIX_pr.png (the best runs' curves), all or nothing.\n"
      "\n"
      "Options:\n"
      "  --vary Key=v1,v2  a key and its values (repeatable); ';' separates values holding commas\n"
      "                    (Fusion_weights=1,1;2,1); '+' fuses descriptors (HOG+LDB). Output,\n"
      "                    Scale, SNAPS and odometry keys cannot be varied.\n"
      "  --output PREFIX   where the files go (default: Evaluation_name, else \"sweep\")\n"
      "  --rank-by FIGURE  auc (default), recall_at_100p, recall_at_1, max_f1, average_precision\n"
      "                    (need ground truth); agreement, consistency, distinctiveness (do not)\n"
      "  --best N          runs drawn in the precision-recall figure (default 5)\n"
      "  --set Key=Value   one key for every run    --quiet, --json, --print-config, --version\n"
      "  --help-keys [GROUP], --help-markdown, -h/--help\n"
      "Every combination is checked before the first frame is read. Exit status: 0 success,\n"
      "1 bad configuration, value or input (nothing written), 2 bad command line, 3 internal\n"
      "error, 128 + signal when interrupted.\n"
      "\n",
      {{"Images_path", "folder of the frames (the reference traversal)"},
       {"Images_path_2", "folder of a second traversal, matched against the first"},
       {"Ground_truth_type", "none (empty), " + openable::GroundTruthFormatList(", ")},
       {"Ground_truth", "the ground-truth file"},
       {"Tolerance", "frames of tolerance of a correct match"},
       {"Exclusion", "one sequence: loops are at least this many frames back"},
       {"Evaluation_name", "the files' prefix when --output is not given"},
       {"Threads", "worker threads; 0: every core"}},
      "Example (the presets were chosen this way):\n"
      "  openable_sweep config/presets/across_conditions.txt --set Images_path=A \\\n"
      "      --set Images_path_2=B --set Ground_truth_type=aligned \\\n"
      "      --vary Image_descriptor=LDB,HOG,SIFT --vary Image_sequences=1,5,10,30 \\\n"
      "      --vary Match_score=distance,ratio --output results/sweep\n"
      "\n"};
}

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
      argc, argv, "openable_sweep", Help(), "OpenABLE " + std::string(openable::kVersion),
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
            std::cerr << "openable_sweep: " << openable::ToValidUtf8(line) << "\n";
        };
        const openable::SweepResult result = openable::RunSweep(config, options, progress, log);
        const std::vector<std::string> written = openable::WriteSweep(prefix, result);
        if (command_line.json) {
          std::cout << openable::ProgramJson(
              "openable_sweep", {{"sweep", openable::SweepJson(result, openable::kVersion)}},
              written);
          return 0;
        }
        std::cout << openable::FormatSweepTable(result) << "Wrote:\n";
        for (const std::string& path : written)
          std::cout << "  " << openable::ToValidUtf8(path) << "\n";
        return 0;
      },
      {"--vary", "--output", "--rank-by", "--best"});
}
