// Test_OpenABLE: Config.txt in, normalised distance matrix out. A thin layer over
// openable::Run (OpenABLE/app/run.h).
#include <iostream>
#include <string>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/app/command_line.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "descriptors/registry.h"

namespace {

// A function, not a constant: the descriptors and ground-truth formats come from their registries.
openable::ProgramHelp Help() {
  return {
      "Usage: Test_OpenABLE [Config.txt] [--set Key=Value ...] [options]\n"
      "\n"
      "Computes the normalised distance matrix (Eq. 5 of the OpenABLE paper) between every pair\n"
      "of frames of an image folder, a video, or two traversals of a route, writes it (.npy,\n"
      "text, colour PNG) and, given ground truth, evaluates it (precision-recall, HTML report).\n"
      "Start from a preset: config/presets/*.txt (README.md, \"Use\").\n"
      "\n"
      "Options:\n"
      "  --set Key=Value   override one key of Config.txt (repeatable; also without a file)\n"
      "  --quiet           no progress lines      --json   the final report as JSON on stdout\n"
      "  --print-config    print the configuration in effect and exit\n"
      "  --help-keys [GROUP], --help-markdown, --version, -h/--help\n"
      "  mpirun -np K Test_OpenABLE Config.txt   the same run spread over K processes\n"
      "Exit status: 0 success, 1 bad configuration or input (nothing written), 2 bad command\n"
      "line, 3 internal error, 128 + signal when interrupted (temporaries removed).\n"
      "\n",
      {{"Images_path", "folder of the frames (the reference traversal)"},
       {"Images_path_2", "folder of a second traversal, matched against the first"},
       {"Frame_mode", "0 image folders, 1 a video (Video_path_1), 3 a ROS 1 bag"},
       {"Image_descriptor",
        openable::JoinStrings(openable::RegisteredDescriptorNames(), ", ") + "; A+B fuses"},
       {"Image_sequences", "frames summed along the diagonal per place (1: single frames)"},
       {"Auto", "1: choose the settings from the data itself (two traversals)"},
       {"Match_score", "distance or ratio: how confident a best match is"},
       {"Npy_name", "the matrix as .npy (also Txt_name, text)"},
       {"Png_name", "the matrix as a colour image (Matrix_color)"},
       {"Ground_truth_type", "none (empty), " + openable::GroundTruthFormatList(", ")},
       {"Ground_truth", "the ground-truth file"},
       {"Tolerance", "frames of tolerance of a correct match"},
       {"Evaluation_name", "prefix of the PR figure, curves and JSON"},
       {"Report_name", "all of it as one HTML page"},
       {"Threads", "worker threads; 0: every core"}},
      "Example (the bundled sample, two seasons of the Nordland railway):\n"
      "  Test_OpenABLE config/presets/across_conditions.txt \\\n"
      "    --set Images_path=examples/data/nordland_sample/summer \\\n"
      "    --set Images_path_2=examples/data/nordland_sample/winter \\\n"
      "    --set Ground_truth_type=aligned --set Report_name=results/report.html\n"
      "\n"};
}

}  // namespace

int main(int argc, char** argv) {
  openable::KeepFrameBuffersOnTheHeap();
  return openable::RunConfigProgram(
      argc, argv, "Test_OpenABLE", Help(), "OpenABLE " + std::string(openable::kVersion),
      [](const openable::Config& config, const openable::CommandLine& command_line,
         openable::ProgressReporter& progress) {
        // --quiet leaves out the auto mode's line per candidate (the report lists them all).
        const bool quiet = command_line.quiet;
        const auto log = [quiet](const std::string& line) {
          if (!quiet || line.rfind("auto: ", 0) != 0)
            std::cerr << "Test_OpenABLE: " << openable::ToValidUtf8(line) << "\n";
        };
        const openable::RunOutcome outcome = openable::Run(config, progress, log);
        std::cout << (command_line.json ? openable::EncodeRunJson(config, outcome)
                                        : openable::FormatRunReport(config, outcome));
        return 0;
      },
      {}, /*spreads_over_processes=*/true);
}
