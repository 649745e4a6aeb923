// openable_snaps: the SNAPS add-on from the command line, a thin layer over
// openable::snaps::RunChain (OpenABLE/app/snaps_chain.h). A drifting trajectory plus loop matches
// (from SNAPS's own search on the images, a pairs file, or an OpenABLE matrix) give corrected
// trajectories (the paper's discounted update, a pose graph, or both), their error against a
// ground truth, a plot and the latencies. Keys: the SNAPS group of Config.txt
// (docs/configuration.md, docs/snaps.md).
#include <iostream>
#include <string>
#include <vector>

#include "OpenABLE/app/command_line.h"
#include "OpenABLE/app/run.h"
#include "OpenABLE/app/snaps_chain.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/io/json.h"

namespace {

const char* const kUsage =
    "Usage: openable_snaps [Config.txt] [--set Key=Value ...] [options]\n"
    "\n"
    "The SNAPS add-on: corrects a drifting visual-odometry trajectory (Snaps_trajectory) with\n"
    "loop matches (Snaps_loops: SNAPS's own search on the images, a pairs file, or the matrix\n"
    "of an OpenABLE run), by the paper's discounted update (Eq. 6) and/or a pose graph\n"
    "(Snaps_corrector); with a ground truth (Snaps_ground_truth) it reports the absolute\n"
    "trajectory error before and after, with and without rigid alignment, and draws them.\n"
    "Outputs (Snaps_output_name = P): P_discounted.txt, P_pose_graph.txt (the input's format),\n"
    "P_loops.csv, P.json, P.png. docs/snaps.md explains every step.\n"
    "\n"
    "Options:\n"
    "  --set Key=Value   override one key (repeatable; also without a file)\n"
    "  --quiet           no progress lines\n"
    "  --json            print the report as one JSON object on stdout (for scripts)\n"
    "  --print-config    print the configuration in effect and exit\n"
    "  -h, --help        this help (the SNAPS keys are in the group SNAPS below)\n"
    "\n"
    "Exit status: 0 success, 1 bad configuration or input data, 2 bad command line,\n"
    "3 internal error, 128 + signal when interrupted (temporaries removed).\n"
    "\n"
    "Example (KITTI 00, SO-DSO keyframes, ground-truth loop pairs, pose graph):\n"
    "  openable_snaps --set Snaps_trajectory=seq00/poses_history_file.txt \\\n"
    "    --set Snaps_trajectory_format=kitti-id --set Snaps_world_to_camera=1 \\\n"
    "    --set Snaps_ground_truth=poses/00.txt --set Snaps_loops=pairs \\\n"
    "    --set Snaps_loops_file=loop_pairs/groundTruth_KITTI00.pairs.csv \\\n"
    "    --set Snaps_drop_outside=1 \\\n"
    "    --set Snaps_output_name=out/kitti00\n"
    "\n";

}  // namespace

int main(int argc, char** argv) {
  return openable::RunConfigProgram(
      argc, argv, "openable_snaps", kUsage, "openable_snaps " + std::string(openable::kVersion),
      [](const openable::Config& config, const openable::CommandLine& cl,
         openable::ProgressReporter& progress) {
        const auto say = [&](const std::string& line) {
          if (!cl.quiet) std::cerr << "  " << line << "\n";
        };
        const openable::snaps::ChainResult result = openable::snaps::RunChain(config, progress, say);
        if (cl.json) {
          const std::vector<std::string> paths = openable::snaps::WriteChainOutputs(config, result);
          std::cout << openable::ProgramJson(
              "openable_snaps", {{"snaps", openable::snaps::ChainJson(config, result)}}, paths);
          return 0;
        }
        std::cout << openable::snaps::FormatChainReport(config, result);
        const std::vector<std::string> paths = openable::snaps::WriteChainOutputs(config, result);
        if (!paths.empty()) {
          std::cout << "Wrote:\n";
          for (const auto& path : paths) std::cout << "  " << path << "\n";
        }
        return 0;
      });
}
