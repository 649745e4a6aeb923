// openable_evaluate: evaluates saved distance matrices against ground truth, with the same
// protocols, keys and outputs as Test_OpenABLE's evaluation (docs/evaluation.md). A thin layer
// over OpenABLE/app/evaluate_files.h.
#include <iostream>
#include <string>
#include <vector>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/app/command_line.h"
#include "OpenABLE/app/evaluate_files.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/io/json.h"

namespace {

const char* kUsage =
    "Usage: openable_evaluate --matrix M.npy [--label NAME] [--matrix M2.npy --label NAME2 ...]\n"
    "                         --gt-type TYPE [--ground-truth FILE] [options]\n"
    "\n"
    "Evaluates saved distance matrices against ground truth (docs/evaluation.md): per-query best\n"
    "match (AUC, R@100P, max F1, R@1/5/10) and ABLE-P cells (average precision); with --protocol\n"
    "also VPR-Bench's and VPR_Tutorial's figures, as their code computes them. Prints a table;\n"
    "--output writes PREFIX.json, PREFIX_pr.png and per matrix its curves (CSV) and overlay.\n"
    "\n"
    "Matrices: .npy (any numeric dtype), text (.txt/.csv), normalised by their maximum (Eq. 5).\n"
    "Not square: queries (rows) x references. Square: one sequence (loop closure), or two\n"
    "traversals with --reference-frames N (N references, then the queries), or queries x\n"
    "references with --layout query_reference. A matrix with its run's settings beside it\n"
    "(M.npy.json) is evaluated with them, unless a flag overrides one.\n"
    "\n"
    "Options (each is also --set Key=Value with the Config.txt key in brackets):\n"
    "  --matrix FILE           a matrix to evaluate (repeatable)\n"
    "  --label NAME            legend label of the preceding --matrix (default: its file name)\n"
    "  --reference-frames N    square matrix over two traversals, the first N are the reference\n"
    "  --layout query_reference   a square matrix of queries x references\n"
    "  --gt-type TYPE          the ground truth's format [Ground_truth_type]:\n"
    "      @FORMATS@\n"
    "  --ground-truth FILE     ground-truth file; for poses of two traversals, the reference's\n"
    "                          [Ground_truth]\n"
    "  --ground-truth-2 FILE   poses of the query traversal [Ground_truth_2]\n"
    "  --ground-truth-soft F   vpr_tutorial: GTsoft, cells ignored [Ground_truth_soft]\n"
    "  --gt-base 0|1|-1        pairs are 0- or 1-based; -1 reads the header [Ground_truth_base]\n"
    "  --radius R              poses: same place when closer than R (5) [Ground_truth_radius]\n"
    "  --heading DEG           poses: and headings within DEG (-1 off) "
    "[Ground_truth_heading]\n"
    "  --min-gap N             poses, one sequence: frames apart (-1 = Exclusion)\n"
    "                          [Ground_truth_min_gap]\n"
    "  --axes xyz|xz|xy        poses: axes of distance and heading (xyz) [Ground_truth_axes]\n"
    "  --tolerance N           frames of tolerance of a correct match (2) [Tolerance]\n"
    "  --exclusion N           one sequence: candidates N frames back or more (100) [Exclusion]\n"
    "  --vicinity N            ABLE-P temporal vicinity (7) [Vicinity]\n"
    "  --first-frame N         frame number of row 0 in pairs and pose files [Initial_image]\n"
    "  --protocol LIST         @PROTOCOLS@, a comma list, or all\n"
    "                          [Evaluation_protocol]\n"
    "  --output PREFIX         write the files [Evaluation_name]\n"
    "  --report FILE.html      one self-contained HTML page: settings, figures, the matrix with\n"
    "                          the ground truth, the worst cases with their frames from --images\n"
    "                          (--images-2) or --video [Report_name, Report_examples]\n"
    "  --images[-2] DIR        frames of the reference (or only) / query traversal [Images_path]\n"
    "  --video FILE            the frames as one video [Video_path_1; with Frame_mode 1]\n"
    "  --config FILE           take the keys above from a Config.txt first (or give FILE alone)\n"
    "  --set Key=Value         any evaluation key of Config.txt (--help-keys Evaluation)\n"
    "  --quiet, --json         print only errors and files written / one JSON object on stdout\n"
    "  --help, --help-keys [GROUP], --version\n"
    "\n"
    "Examples (KITTI 00 loops within 5 m; 200 x 200 scored three ways with VPR-Bench's file):\n"
    "  openable_evaluate --matrix kitti.npy --gt-type kitti --ground-truth poses/00.txt \\\n"
    "      --axes xz --heading 45 --exclusion 100 --tolerance 3 --output results/kitti\n"
    "  openable_evaluate --matrix m.npy --layout query_reference --gt-type vpr_bench \\\n"
    "      --ground-truth ground_truth_new.npy --tolerance 0 --protocol all\n"
    "\n"
    "Exit status: 0 success, 1 bad input (one line on stderr), 2 bad command line, 3 bug.\n";

}  // namespace

// The usage, with the ground-truth formats of the registry.
std::string Usage() {
  std::string usage = kUsage;
  usage.replace(usage.find("@FORMATS@"), 9, openable::GroundTruthFormatList(", "));
  usage.replace(usage.find("@PROTOCOLS@"), 11, openable::EvaluationProtocolNames());
  return usage;
}

int main(int argc, char** argv) {
  openable::InstallInterruptCleanup("openable_evaluate");  // signals remove the temporaries
  // One process: started by mpirun with several, process 0 says so and every process stops.
  if (const openable::Cluster& cluster = openable::Cluster::Get(); cluster.LaunchSize() > 1) {
    if (cluster.LaunchRank() == 0)
      std::cerr << "openable_evaluate: error: openable_evaluate runs as one process, but mpirun "
                   "started "
                << cluster.LaunchSize()
                << "; expected one (Test_OpenABLE spreads a run over processes)\n";
    return openable::kExitInputError;
  }
  openable::EvaluateCommandLine command_line;
  const std::string error = openable::ParseEvaluateCommandLine(argc, argv, command_line);
  if (!error.empty()) {
    std::cerr << openable::ToValidUtf8(error) << "\n";
    return openable::kExitUsageError;
  }
  if (command_line.help_keys)
    return openable::AnswerHelpKeys("openable_evaluate", command_line.help_group);
  if (command_line.help || command_line.version) {
    std::cout << (command_line.help ? Usage()
                                    : "OpenABLE " + std::string(openable::kVersion) + "\n");
    return 0;
  }
  return openable::RunProgram("openable_evaluate", [&] {
    const openable::EvaluatedFiles evaluated = openable::EvaluateFiles(command_line);
    if (!command_line.quiet && !command_line.json)
      std::cout << openable::FormatEvaluationTable(evaluated.evaluation.settings,
                                                   evaluated.evaluation.runs);
    const std::vector<std::string> paths =
        openable::WriteEvaluatedFiles(evaluated, command_line.matrices);
    // After the files are written: a run that fails says so in its one line alone.
    for (const std::string& note : evaluated.notes)
      std::cerr << "openable_evaluate: note: " << openable::ToValidUtf8(note) << "\n";
    for (const openable::EvaluatedRun& run : evaluated.evaluation.runs)
      for (const std::string& warning : run.warnings)
        std::cerr << "openable_evaluate: warning: " << openable::ToValidUtf8(run.label) << ": "
                  << openable::ToValidUtf8(warning) << "\n";
    if (command_line.json) {
      std::cout << openable::ProgramJson(
          "openable_evaluate",
          {{"evaluation", openable::EvaluationJson(evaluated.evaluation.settings,
                                                   evaluated.evaluation.runs, openable::kVersion)}},
          paths);
      return 0;
    }
    if (paths.empty()) return 0;
    std::cout << "Wrote:\n";
    for (const auto& p : paths) std::cout << "  " << openable::ToValidUtf8(p) << "\n";
    return 0;
  });
}
