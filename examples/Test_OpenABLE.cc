// Test_OpenABLE: Config.txt in, normalised distance matrix out. A thin layer over
// openable::Run (OpenABLE/app/run.h).
#include <iostream>
#include <string>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/app/command_line.h"

namespace {

const char* kUsage =
    "Usage: Test_OpenABLE [Config.txt] [--set Key=Value ...] [options]\n"
    "\n"
    "Computes the normalised distance matrix (Eq. 5 of the OpenABLE paper) between every pair\n"
    "of frames of an image folder, a video, or two traversals of a route, and writes it as\n"
    "text, .npy and colour PNG (see Txt_name, Npy_name, Png_name).\n"
    "\n"
    "Options:\n"
    "  --set Key=Value   override one key of Config.txt (repeatable; also without a file)\n"
    "  --quiet           no progress lines (errors and the final report are still printed)\n"
    "  --json            print the final report as one JSON object on stdout (for scripts;\n"
    "                    docs/output_formats.md, \"Reports as JSON\")\n"
    "  --print-config    print the configuration in effect (Config.txt format) and exit\n"
    "  --help-markdown   print the key reference as Markdown (docs/configuration.md)\n"
    "  --version         print the version\n"
    "  -h, --help        this help\n"
    "\n"
    "Spread over processes (one machine or many, with Open MPI; docs/distributed.md):\n"
    "  mpirun -np K Test_OpenABLE Config.txt   the same run, the same outputs\n"
    "\n"
    "Exit status: 0 success, 1 bad configuration or input data (or an output that cannot be\n"
    "written: no output of the run is kept), 2 bad command line, 3 internal error,\n"
    "128 + signal when interrupted (130 SIGINT, 143 SIGTERM, 129 SIGHUP; temporaries removed).\n"
    "\n"
    "Example:\n"
    "  Test_OpenABLE config/Config.txt --set Image_sequences=20 --set Image_descriptor=HOG\n"
    "\n"
    "Configuration keys (Config.txt: one 'Key: value' per line, '#' comments):\n";

}  // namespace

int main(int argc, char** argv) {
  openable::KeepFrameBuffersOnTheHeap();
  return openable::RunConfigProgram(
      argc, argv, "Test_OpenABLE", kUsage, "OpenABLE " + std::string(openable::kVersion),
      [](const openable::Config& config, const openable::CommandLine& command_line,
         openable::ProgressReporter& progress) {
        // --quiet leaves out the auto mode's line per candidate (the report lists them all).
        const bool quiet = command_line.quiet;
        const auto log = [quiet](const std::string& line) {
          if (!quiet || line.rfind("auto: ", 0) != 0)
            std::cerr << "Test_OpenABLE: " << line << "\n";
        };
        const openable::RunOutcome outcome = openable::Run(config, progress, log);
        std::cout << (command_line.json ? openable::EncodeRunJson(config, outcome)
                                        : openable::FormatRunReport(config, outcome));
        return 0;
      },
      {}, /*spreads_over_processes=*/true);
}
