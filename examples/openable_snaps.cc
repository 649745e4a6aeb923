// openable_snaps: the SNAPS add-on from the command line. A drifting trajectory plus loop
// matches (from SNAPS's own search on the images, a pairs file, or an OpenABLE matrix) give
// corrected trajectories (the paper's discounted update, a pose graph, or both), their error
// against a ground truth, a plot and the latencies. Keys: the SNAPS group of Config.txt
// (docs/configuration.md, docs/snaps.md).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core/utils/logger.hpp>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/exports.h"
#include "OpenABLE/snaps/discounted.h"
#include "OpenABLE/snaps/loop_search.h"
#include "OpenABLE/snaps/loops.h"
#include "OpenABLE/snaps/plot.h"
#include "OpenABLE/snaps/pose_graph.h"
#include "OpenABLE/snaps/trajectory.h"
#include "config/command_line.h"
#include "config/config.h"

namespace {

namespace snaps = openable::snaps;

constexpr int kInputError = 1;
constexpr int kUsageError = 2;
constexpr int kInternalError = 3;

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
    "  --print-config    print the configuration in effect and exit\n"
    "  -h, --help        this help (the SNAPS keys are in the group SNAPS below)\n"
    "\n"
    "Exit status: 0 success, 1 bad configuration or input data, 2 bad command line,\n"
    "3 internal error.\n"
    "\n"
    "Example (KITTI 00, SO-DSO keyframes, ground-truth loop pairs, pose graph):\n"
    "  openable_snaps --set Snaps_trajectory=seq00/poses_history_file.txt \\\n"
    "    --set Snaps_trajectory_format=kitti-id --set Snaps_world_to_camera=1 \\\n"
    "    --set Snaps_ground_truth=poses/00.txt --set Snaps_loops=pairs \\\n"
    "    --set Snaps_loops_file=loop_pairs/groundTruth_KITTI00.pairs.csv \\\n"
    "    --set Snaps_drop_outside=1 \\\n"
    "    --set Snaps_output_name=out/kitti00\n"
    "\n";

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Errors of one trajectory against the ground truth, unaligned and aligned.
struct Errors {
  snaps::TrajectoryError raw, aligned;
};

Errors Evaluate(const snaps::Trajectory& t, const snaps::Trajectory& truth,
                const std::vector<int>& association) {
  return {snaps::AbsoluteTrajectoryError(t, truth, association, false),
          snaps::AbsoluteTrajectoryError(t, truth, association, true)};
}

std::string Number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string StatsJson(const snaps::LatencyStats& s) {
  std::ostringstream o;
  o << "{\"count\": " << s.count << ", \"mean_s\": " << Number(s.mean) << ", \"min_s\": "
    << Number(s.min) << ", \"q1_s\": " << Number(s.q1) << ", \"median_s\": " << Number(s.median)
    << ", \"q3_s\": " << Number(s.q3) << ", \"max_s\": " << Number(s.max) << "}";
  return o.str();
}

std::string ErrorJson(const snaps::TrajectoryError& e) {
  std::ostringstream o;
  o << "{\"rmse_m\": " << Number(e.rmse) << ", \"mean_m\": " << Number(e.mean)
    << ", \"median_m\": " << Number(e.median) << ", \"max_m\": " << Number(e.max) << "}";
  return o.str();
}

std::string StatsLine(const snaps::LatencyStats& s) {
  char b[200];
  std::snprintf(b, sizeof b, "%6d  mean %9.3f ms  [min %.3f, q1 %.3f, median %.3f, q3 %.3f, max %.3f] ms",
                s.count, s.mean * 1e3, s.min * 1e3, s.q1 * 1e3, s.median * 1e3, s.q3 * 1e3,
                s.max * 1e3);
  return b;
}

std::string CsvOfLoops(const snaps::Trajectory& t, const std::vector<snaps::LoopPair>& loops) {
  std::ostringstream o;
  o << "# query_frame,reference_frame,similarity (frame numbers of the trajectory)\n";
  for (const auto& l : loops)
    o << t.frame_ids[static_cast<size_t>(l.query)] << ","
      << t.frame_ids[static_cast<size_t>(l.reference)] << "," << Number(l.similarity) << "\n";
  return o.str();
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

int Run(const openable::Config& c, bool quiet) {
  openable::CheckSnapsConfig(c);
  using Clock = std::chrono::steady_clock;
  auto say = [&](const std::string& line) {
    if (!quiet) std::cerr << "  " << line << "\n";
  };

  // Inputs.
  const snaps::Trajectory input = openable::WithKey("Snaps_trajectory", [&] {
    return snaps::ReadTrajectory(
        c.snaps_trajectory,
        snaps::ParseTrajectoryFormat(c.snaps_trajectory_format, "Snaps_trajectory_format"),
        c.snaps_world_to_camera == 1);
  });
  snaps::Trajectory truth;
  std::vector<int> association;
  const bool evaluate = !c.snaps_ground_truth.empty();
  if (evaluate) {
    truth = openable::WithKey("Snaps_ground_truth", [&] {
      return snaps::ReadTrajectory(
          c.snaps_ground_truth,
          snaps::ParseTrajectoryFormat(c.snaps_ground_truth_format, "Snaps_ground_truth_format"));
    });
    association = snaps::AssociateWithTruth(input, truth, c.snaps_time_tolerance,
                                            "Snaps_ground_truth");
  }

  snaps::SearchOptions search;
  search.thumbnail_scale = c.snaps_thumbnail_scale;
  search.window = c.snaps_window;
  search.min_similarity = c.snaps_min_similarity;
  search.max_yaw_difference_deg = c.snaps_yaw_limit;
  search.radius = c.snaps_radius;
  search.frame_distance = c.snaps_frame_distance;
  search.attempts = c.snaps_attempts;
  search.discount.discount_length = c.snaps_discount_length;
  search.discount.pause = c.snaps_pause;
  search.vertical = Lower(c.snaps_axes) == "xy" ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();

  // Loops.
  const std::string source = Lower(c.snaps_loops);
  std::vector<snaps::LoopPair> loops;
  snaps::ImageSearchResult searched;
  int dropped = 0, outside = 0;
  auto t = Clock::now();
  if (source == "pairs") {
    try {
      loops = openable::WithKey("Snaps_loops_file", [&] {
        return snaps::LoopsFromCsv(c.snaps_loops_file, input, c.snaps_keyframe_tolerance,
                                   &dropped, c.snaps_drop_outside == 1 ? &outside : nullptr);
      });
    } catch (const openable::InputError& e) {
      const std::string m = e.what();
      if (m.find("outside the trajectory") == std::string::npos) throw;
      throw openable::InputError(m + " (Snaps_drop_outside 1 drops such pairs)");
    }
    if (c.snaps_middle_of_runs == 1) loops = snaps::MiddleOfRuns(loops, input);
  } else if (source == "matrix") {
    snaps::MatrixLoopOptions m;
    m.threshold = c.snaps_matrix_threshold;
    m.exclusion = c.snaps_frame_distance;
    m.initial = c.initial_image;
    m.tolerance = c.snaps_keyframe_tolerance;
    loops = openable::WithKey("Snaps_loops_file",
                              [&] { return snaps::LoopsFromMatrix(c.snaps_loops_file, input, m); });
  } else {
    const std::string folder = c.snaps_images.empty() ? c.images_path : c.snaps_images;
    say("searching loops on thumbnails of " + folder + " (" + std::to_string(input.Size()) +
        " poses)");
    searched = openable::WithKey(c.snaps_images.empty() ? "Images_path" : "Snaps_images", [&] {
      return snaps::SearchLoopsInImages(folder, c.images_format, c.initial_image, input, search);
    });
    loops = searched.loops;
  }
  const double loop_seconds = Seconds(t);
  say(std::to_string(loops.size()) + " loop pairs (" + source + ")" +
      (dropped > 0 ? ", " + std::to_string(dropped) + " pairs with a frame that is not a pose dropped"
                   : std::string()) +
      (outside > 0 ? ", " + std::to_string(outside) + " pairs outside the trajectory dropped"
                   : std::string()));

  // Corrections.
  const std::string corrector = Lower(c.snaps_corrector);
  const bool want_discounted = corrector != "pose-graph";
  const bool want_graph = corrector != "discounted";
  snaps::Trajectory discounted, graph;
  std::vector<snaps::LoopPair> closed;
  double discounted_seconds = 0;
  if (want_discounted) {
    t = Clock::now();
    if (source == "search") {
      discounted = searched.corrected;
      closed = loops;
    } else {
      snaps::DiscountOptions d = search.discount;
      discounted = snaps::CorrectDiscounted(input, loops, d);
      closed = snaps::ClosedLoops(loops, d.pause);
    }
    discounted_seconds = Seconds(t);
  }
  snaps::PoseGraphReport graph_report;
  if (want_graph) {
    snaps::PoseGraphOptions g;
    g.loop_weight = c.snaps_loop_weight;
    g.odometry_translation_weight = c.snaps_odometry_translation_weight;
    g.odometry_rotation_weight = c.snaps_odometry_rotation_weight;
    g.robust_kernel = snaps::ParseRobustKernel(c.snaps_robust_kernel, "Snaps_robust_kernel");
    g.robust_scale = c.snaps_robust_scale;
    say("pose graph: " + std::to_string(input.Size()) + " poses, " +
        std::to_string(loops.size()) + " loop edges");
    graph = snaps::CorrectPoseGraph(input, loops, g, &graph_report);
  }

  // Report.
  std::cout << "openable_snaps " << openable::kVersion << ": " << input.Size() << " poses ("
            << snaps::TrajectoryFormatName(input.format) << ", frames " << input.frame_ids.front()
            << "-" << input.frame_ids.back() << ") from \"" << c.snaps_trajectory << "\"\n";
  std::cout << "  loops: " << loops.size() << " pairs from " << source << " ("
            << Number(loop_seconds) << " s";
  if (dropped > 0) std::cout << "; " << dropped << " pairs with a frame that is not a pose dropped";
  if (outside > 0) std::cout << "; " << outside << " pairs outside the trajectory dropped";
  std::cout << ")";
  if (want_discounted)
    std::cout << "; discounted update closes " << closed.size() << " (pause " << c.snaps_pause
              << ", K " << c.snaps_discount_length << ")";
  std::cout << "\n";
  if (want_graph)
    std::cout << "  pose graph: " << graph_report.loop_edges << " loop edges, "
              << graph_report.iterations << " iterations, cost " << Number(graph_report.initial_cost)
              << " -> " << Number(graph_report.final_cost) << ", " << Number(graph_report.seconds)
              << " s" << (graph_report.converged ? "" : " (not converged: max iterations)") << "\n";

  std::ostringstream json;
  json << "{\n  \"trajectory\": \"" << c.snaps_trajectory << "\",\n  \"poses\": " << input.Size()
       << ",\n  \"loop_source\": \"" << source << "\",\n  \"loops\": " << loops.size()
       << ",\n  \"loops_closed_by_discounted_update\": " << closed.size()
       << ",\n  \"pose_graph\": {\"loop_edges\": " << graph_report.loop_edges
       << ", \"iterations\": " << graph_report.iterations << ", \"initial_cost\": "
       << Number(graph_report.initial_cost) << ", \"final_cost\": "
       << Number(graph_report.final_cost) << ", \"seconds\": " << Number(graph_report.seconds)
       << "}";
  if (evaluate) {
    struct Row {
      const char* name;
      const snaps::Trajectory* t;
    };
    std::vector<Row> rows = {{"input", &input}};
    if (want_discounted) rows.push_back({"discounted", &discounted});
    if (want_graph) rows.push_back({"pose_graph", &graph});
    std::cout << "Absolute trajectory error against \"" << c.snaps_ground_truth << "\" (metres):\n"
              << "  trajectory      mean dev.      RMSE       max   | aligned: mean dev.   RMSE\n";
    json << ",\n  \"errors\": {";
    double input_mean = 0;
    for (size_t r = 0; r < rows.size(); ++r) {
      const Errors e = Evaluate(*rows[r].t, truth, association);
      if (r == 0) input_mean = e.raw.mean;
      char line[200];
      std::snprintf(line, sizeof line, "  %-12s %10.3f %10.3f %9.3f   | %16.3f %8.3f", rows[r].name,
                    e.raw.mean, e.raw.rmse, e.raw.max, e.aligned.mean, e.aligned.rmse);
      std::cout << line;
      if (r > 0 && input_mean > 0)
        std::cout << "   (mean deviation " << std::showpos
                  << Number(100.0 * (e.raw.mean - input_mean) / input_mean) << std::noshowpos
                  << " %)";
      std::cout << "\n";
      json << (r ? ", " : "") << "\n    \"" << rows[r].name << "\": {\"unaligned\": "
           << ErrorJson(e.raw) << ", \"aligned\": " << ErrorJson(e.aligned) << "}";
    }
    json << "\n  }";
  }
  if (source == "search") {
    std::vector<double> none, found, all;
    for (const auto& s : searched.steps) {
      all.push_back(s.seconds);
      (s.loop ? found : none).push_back(s.seconds);
    }
    const auto s_none = snaps::Summarize(none), s_found = snaps::Summarize(found),
               s_all = snaps::Summarize(all), s_corr = snaps::Summarize(searched.correction_seconds),
               s_thumb = snaps::Summarize(searched.thumbnail_seconds);
    std::cout << "Latency per frame (paper, Fig. 5: no candidate 2.94e-6 s, loop closure 0.027 s):\n"
              << "  search, no loop    " << StatsLine(s_none) << "\n"
              << "  search, loop found " << StatsLine(s_found) << "\n"
              << "  correction (Eq. 6) " << StatsLine(s_corr) << "\n"
              << "  thumbnail (read)   " << StatsLine(s_thumb) << "\n";
    json << ",\n  \"latency\": {\"search_no_loop\": " << StatsJson(s_none)
         << ", \"search_loop_found\": " << StatsJson(s_found) << ", \"search_all\": "
         << StatsJson(s_all) << ", \"correction\": " << StatsJson(s_corr)
         << ", \"thumbnail\": " << StatsJson(s_thumb) << "}";
  } else if (want_discounted && !closed.empty()) {
    std::cout << "  discounted update: " << Number(discounted_seconds) << " s for "
              << closed.size() << " loops\n";
  }
  json << "\n}\n";

  // Outputs, all or nothing.
  if (!c.snaps_output_name.empty()) {
    const std::string p = c.snaps_output_name;
    openable::OutputBatch batch;
    if (want_discounted)
      batch.Stage("Snaps_output_name", p + "_discounted.txt", snaps::EncodeTrajectory(discounted));
    if (want_graph)
      batch.Stage("Snaps_output_name", p + "_pose_graph.txt", snaps::EncodeTrajectory(graph));
    batch.Stage("Snaps_output_name", p + "_loops.csv", CsvOfLoops(input, loops));
    batch.Stage("Snaps_output_name", p + ".json", json.str());
    // The plot: the pose graph's result (or the one corrector's), and the discounted update's
    // in a second figure when both ran.
    auto figure = [&](const snaps::Trajectory& corrected, const std::string& label) {
      snaps::TrajectoryPlot plot;
      plot.truth = evaluate ? &truth : nullptr;
      plot.input = &input;
      plot.corrected = &corrected;
      plot.corrected_label = label;
      plot.loops = loops;
      plot.axes = Lower(c.snaps_axes);
      plot.title = "SNAPS, " + std::to_string(loops.size()) + " loops (" + source + "): " +
                   std::filesystem::path(c.snaps_trajectory).filename().string();
      return openable::EncodePng(snaps::RenderTrajectories(plot));
    };
    if (want_graph) batch.Stage("Snaps_output_name", p + ".png", figure(graph, "pose graph"));
    if (want_discounted)
      batch.Stage("Snaps_output_name", p + (want_graph ? "_discounted.png" : ".png"),
                  figure(discounted, "discounted update (Eq. 6)"));
    const std::vector<std::string> paths = batch.Paths();
    batch.Commit();
    std::cout << "Wrote:\n";
    for (const auto& path : paths) std::cout << "  " << path << "\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  openable::CommandLine cl;
  const std::string usage_error = openable::ParseCommandLine(argc, argv, "openable_snaps", cl);
  if (cl.help) {
    std::cout << kUsage << openable::ConfigHelpText();
    return 0;
  }
  if (cl.help_markdown) {
    std::cout << openable::ConfigMarkdownReference();
    return 0;
  }
  if (cl.version) {
    std::cout << "openable_snaps " << openable::kVersion << "\n";
    return 0;
  }
  if (!usage_error.empty()) {
    std::cerr << usage_error << "\n";
    return kUsageError;
  }
  try {
    openable::Config config = openable::ConfigOf(cl);
    if (cl.print_config) {
      std::cout << openable::FormatConfig(config);
      return 0;
    }
    return Run(config, cl.quiet);
  } catch (const openable::InputError& e) {
    std::cerr << "openable_snaps: error: " << e.what() << "\n";
    return kInputError;
  } catch (const std::exception& e) {
    std::cerr << "openable_snaps: internal error (please report): " << e.what() << "\n";
    return kInternalError;
  }
}
