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
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/io/json.h"

namespace {

const openable::ProgramHelp kHelp = {
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
    "  --quiet           no progress lines      --json   the report as JSON on stdout\n"
    "  --print-config    print the configuration in effect and exit\n"
    "  --help-keys [GROUP] (SNAPS, Odometry: every key of SNAPS), --version, -h/--help\n"
    "Exit status: 0 success, 1 bad configuration or input data, 2 bad command line,\n"
    "3 internal error, 128 + signal when interrupted (temporaries removed).\n"
    "\n",
    {{"Snaps_trajectory", "the drifting trajectory (or Snaps_odometry computes one)"},
     {"Snaps_trajectory_format", "its format: kitti, kitti-id (keyframes) or tum"},
     {"Snaps_world_to_camera", "1 when its poses map the world to the camera (SO-DSO)"},
     {"Snaps_ground_truth", "poses to measure the error against (optional)"},
     {"Snaps_loops", "loops from: search, openable, pairs or matrix"},
     {"Snaps_loops_file", "the pairs file or the OpenABLE matrix of the loops"},
     {"Snaps_corrector", "discounted (Eq. 6), pose-graph or both"},
     {"Snaps_images", "the frames, for SNAPS's own loop search (search, openable)"},
     {"Snaps_axes", "ground plane of the plot and the yaw: xz (KITTI) or xy"},
     {"Snaps_output_name", "prefix P of the outputs"}},
    "Example (KITTI 00, SO-DSO keyframes, ground-truth loop pairs, pose graph):\n"
    "  openable_snaps --set Snaps_trajectory=seq00/poses_history_file.txt \\\n"
    "    --set Snaps_trajectory_format=kitti-id --set Snaps_world_to_camera=1 \\\n"
    "    --set Snaps_ground_truth=poses/00.txt --set Snaps_loops=pairs \\\n"
    "    --set Snaps_loops_file=loop_pairs/groundTruth_KITTI00.pairs.csv \\\n"
    "    --set Snaps_drop_outside=1 --set Snaps_output_name=out/kitti00\n"
    "\n"};

}  // namespace

int main(int argc, char** argv) {
  return openable::RunConfigProgram(
      argc, argv, "openable_snaps", kHelp, "openable_snaps " + std::string(openable::kVersion),
      [](const openable::Config& config, const openable::CommandLine& cl,
         openable::ProgressReporter& progress) {
        const auto say = [&](const std::string& line) {
          if (!cl.quiet) std::cerr << "  " << openable::ToValidUtf8(line) << "\n";
        };
        const openable::snaps::ChainResult result =
            openable::snaps::RunChain(config, progress, say);
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
          for (const auto& path : paths) std::cout << "  " << openable::ToValidUtf8(path) << "\n";
        }
        return 0;
      });
}
