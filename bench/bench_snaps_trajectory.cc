// Pose-graph correction of the SO-DSO trajectories of KITTI 00 and 06 with the ground-truth loop
// pairs: prints the figures of docs/benchmarks.md ("SNAPS and odometry") and writes the top views.
// Usage: bench_snaps_trajectory [output folder, default .]
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "OpenABLE/snaps/loops.h"
#include "OpenABLE/snaps/plot.h"
#include "OpenABLE/snaps/pose_graph.h"
#include "OpenABLE/snaps/trajectory.h"

using namespace openable::snaps;  // NOLINT: a small program

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : ".";
  const std::string root = std::string(OPENABLE_DATASETS_DIR) + "/kitti_trajectories";
  const struct {
    const char* sequence;
    const char* pairs;
  } runs[] = {{"00", "groundTruth_KITTI00.pairs.csv"}, {"06", "kitti06GroundTruth.pairs.csv"}};
  try {
    for (const auto& run : runs) {
      const std::string s = run.sequence;
      const Trajectory vo = ReadTrajectory(root + "/vo_so_dso/seq" + s + "/poses_history_file.txt",
                                           TrajectoryFormat::kKittiWithId, true);
      const Trajectory truth =
          ReadTrajectory(root + "/poses/" + s + ".txt", TrajectoryFormat::kKitti);
      const std::vector<int> association = AssociateWithTruth(vo, truth, 0, "truth");
      int dropped = 0, outside = 0;
      const std::vector<LoopPair> pairs =
          LoopsFromCsv(root + "/loop_pairs/" + run.pairs, vo, 0, &dropped, &outside);
      for (const bool middle : {true, false}) {
        const std::vector<LoopPair> loops = middle ? MiddleOfRuns(pairs, vo) : pairs;
        for (const RobustKernel kernel : {RobustKernel::kHuber, RobustKernel::kNone}) {
          PoseGraphOptions options;
          options.robust_kernel = kernel;
          PoseGraphReport report;
          const Trajectory corrected = CorrectPoseGraph(vo, loops, options, &report);
          const auto e = [&](const Trajectory& t, bool align) {
            return AbsoluteTrajectoryError(t, truth, association, align);
          };
          std::printf(
              "%s | %s | %s | %zu of %zu | %.2f -> %.2f (%+.0f %%) | %.2f -> %.2f | "
              "%.2f -> %.2f | %.2f -> %.2f | %d | %.3f s\n",
              s.c_str(), middle ? "middle of runs" : "all on keyframes",
              RobustKernelName(kernel).c_str(), loops.size(), pairs.size(), e(vo, false).mean,
              e(corrected, false).mean, -100 * (1 - e(corrected, false).mean / e(vo, false).mean),
              e(vo, false).rmse, e(corrected, false).rmse, e(vo, true).mean,
              e(corrected, true).mean, e(vo, true).rmse, e(corrected, true).rmse, report.iterations,
              report.seconds);
          if (middle && kernel == RobustKernel::kHuber) {
            // Upper bound of any loop-based correction here: the same loops with their exact
            // relative pose taken from the ground truth (what a perfect geometric verification
            // would measure), as full 6-DoF loop edges.
            std::vector<RelativeLoop> exact;
            for (const LoopPair& l : loops)
              exact.push_back({l.query, l.reference,
                               truth.poses[association[l.reference]].inverse() *
                                   truth.poses[association[l.query]]});
            PoseGraphReport oracle_report;
            const Trajectory oracle = CorrectPoseGraph(vo, {}, exact, options, &oracle_report);
            std::printf(
                "%s | exact relative poses from the ground truth (upper bound) | %s | %zu "
                "| %.2f -> %.2f (%+.0f %%) | %.2f -> %.2f | %.2f -> %.2f | %.2f -> %.2f "
                "| %d | %.3f s\n",
                s.c_str(), RobustKernelName(kernel).c_str(), exact.size(), e(vo, false).mean,
                e(oracle, false).mean, -100 * (1 - e(oracle, false).mean / e(vo, false).mean),
                e(vo, false).rmse, e(oracle, false).rmse, e(vo, true).mean, e(oracle, true).mean,
                e(vo, true).rmse, e(oracle, true).rmse, oracle_report.iterations,
                oracle_report.seconds);
            TrajectoryPlot plot;
            plot.truth = &truth;
            plot.input = &vo;
            plot.corrected = &corrected;
            plot.loops = loops;
            char label[128];
            std::snprintf(label, sizeof(label), " (mean %.1f m)", e(vo, false).mean);
            plot.input_label = "SO-DSO keyframes" + std::string(label);
            std::snprintf(label, sizeof(label), " (mean %.1f m)", e(corrected, false).mean);
            plot.corrected_label = "pose graph" + std::string(label);
            plot.truth_label = "KITTI ground truth";
            plot.title = "KITTI " + s + ": SO-DSO corrected with ground-truth loops";
            cv::imwrite(out + "/snaps_kitti" + s + ".png", RenderTrajectories(plot));
          }
        }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
