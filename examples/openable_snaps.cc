// openable_snaps: the SNAPS add-on from the command line. A drifting trajectory plus loop
// matches (from SNAPS's own search on the images, a pairs file, or an OpenABLE matrix) give
// corrected trajectories (the paper's discounted update, a pose graph, or both), their error
// against a ground truth, a plot and the latencies. Keys: the SNAPS group of Config.txt
// (docs/configuration.md, docs/snaps.md).
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core/utils/logger.hpp>

#include "OpenABLE/OpenABLE.h"
#include "OpenABLE/run/exports.h"
#include "OpenABLE/run/interrupt.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/odometry/calibration.h"
#include "OpenABLE/odometry/mono_odometry.h"
#include "OpenABLE/odometry/stereo_odometry.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/rectification.h"
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

// What the odometry did, for the report.
struct OdometryReport {
  std::string kind;                 // mono, stereo
  std::string scale;                // where the scale came from
  std::vector<double> seconds;      // per frame
  int failed = 0;                   // steps that kept the previous motion
  std::string first_failure;
};

// Frames [Initial_image, Final_image) of a folder, in natural order.
std::vector<std::string> FramesOf(const openable::Config& c, const std::string& folder,
                                  const std::string& key) {
  return openable::WithKey(key, [&] {
    const std::vector<std::string> all = openable::ListImages(folder, c.images_format);
    const int first = c.initial_image;
    const int last = c.final_image < 0 ? static_cast<int>(all.size())
                                       : std::min(c.final_image, static_cast<int>(all.size()));
    if (first >= last)
      throw openable::InputError("folder " + openable::Quoted(folder) + " holds " +
                                 std::to_string(all.size()) + " images; Initial_image " +
                                 std::to_string(first) + " leaves none");
    return std::vector<std::string>(all.begin() + first, all.begin() + last);
  });
}

cv::Mat GrayOf(const std::string& path) { return openable::ToGray8(openable::ReadImageFile(path)); }

// Snaps_odometry: the trajectory of the frames computed from the images (issue 7).
snaps::Trajectory ComputeOdometry(const openable::Config& c, const snaps::Trajectory* truth,
                                  openable::ProgressReporter& progress, OdometryReport& report) {
  namespace odo = openable::odometry;
  const std::string kind = Lower(c.snaps_odometry);
  report.kind = kind;
  snaps::Trajectory t;
  t.format = c.initial_image == 0 ? snaps::TrajectoryFormat::kKitti
                                  : snaps::TrajectoryFormat::kKittiWithId;
  auto record = [&](const odo::StepStats& stats, int i, const Eigen::Isometry3d& pose) {
    t.poses.push_back(pose);
    t.frame_ids.push_back(c.initial_image + i);
    report.seconds.push_back(stats.seconds);
    if (!stats.ok) {
      if (report.failed++ == 0)
        report.first_failure = "frame " + std::to_string(c.initial_image + i) + ": " + stats.note;
    }
  };
  if (kind == "mono") {
    const std::string folder = c.snaps_images.empty() ? c.images_path : c.snaps_images;
    const std::vector<std::string> frames =
        FramesOf(c, folder, c.snaps_images.empty() ? "Images_path" : "Snaps_images");
    const odo::KittiCalibration calib = openable::WithKey("Odometry_calibration", [&] {
      return odo::ReadKittiCalibration(c.odometry_calibration, c.odometry_calibration_scale);
    });
    odo::MonoOdometryOptions o;  // 0 or empty keys keep the odometry's defaults
    if (!c.odometry_features.empty()) o.features = c.odometry_features;
    o.max_features = c.odometry_max_features;
    o.ratio_test = c.odometry_ratio_test;
    if (c.odometry_ransac_threshold > 0) o.ransac_threshold_px = c.odometry_ransac_threshold;
    if (c.odometry_min_inliers > 0) o.min_inliers = c.odometry_min_inliers;
    o.Check();
    odo::MonoOdometry odometry(calib.left, o);
    progress.Begin("odometry", static_cast<std::int64_t>(frames.size()), "frames (mono)");
    const std::string scale = Lower(c.odometry_scale);
    report.scale = scale == "truth" ? "step lengths of the ground truth (a single camera cannot measure scale)"
                   : scale == "step" ? "Odometry_step_length " + Number(c.odometry_step_length) + " m per frame"
                                     : "none: unit steps, arbitrary scale";
    std::map<long, int> truth_index;
    if (truth)
      for (int k = 0; k < truth->Size(); ++k) truth_index[truth->frame_ids[static_cast<size_t>(k)]] = k;
    for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
      double step = -1;
      if (scale == "step") step = c.odometry_step_length;
      if (scale == "truth" && i > 0) {
        const long f = c.initial_image + i;
        const auto a = truth_index.find(f - 1), b = truth_index.find(f);
        if (a == truth_index.end() || b == truth_index.end())
          throw openable::InputError("Odometry_scale: truth, but Snaps_ground_truth has no pose of frame " +
                                     std::to_string(a == truth_index.end() ? f - 1 : f) +
                                     "; expected the ground truth of every frame");
        step = (truth->poses[static_cast<size_t>(b->second)].translation() -
                truth->poses[static_cast<size_t>(a->second)].translation()).norm();
      }
      const cv::Mat gray = openable::WithKey("Snaps_images", [&] { return GrayOf(frames[static_cast<size_t>(i)]); });
      const Eigen::Isometry3d pose = odometry.Step(gray, step);
      record(odometry.last(), i, pose);
      progress.Update(i + 1);
    }
    progress.End();
    return t;
  }
  // Stereo.
  const std::vector<std::string> left = FramesOf(c, c.images_path_left, "Images_path_left");
  const std::vector<std::string> right = FramesOf(c, c.images_path_right, "Images_path_right");
  if (left.size() != right.size())
    throw openable::InputError("Images_path_right: " + openable::Quoted(c.images_path_right) + " holds " +
                               std::to_string(right.size()) + " images in the range but Images_path_left " +
                               std::to_string(left.size()) + "; expected one right image per left image");
  odo::Intrinsics intrinsics;
  double baseline = 0;
  std::unique_ptr<openable::StereoRectifier> rectifier;
  if (!c.calibration_path.empty()) {
    const openable::StereoCalibration calibration = openable::WithKey(
        "Calibration_path", [&] { return openable::LoadStereoCalibration(c.calibration_path); });
    const cv::Size size = GrayOf(left.front()).size();
    openable::CheckCalibrationFits(calibration, size, c.calibration_path);
    rectifier = std::make_unique<openable::StereoRectifier>(calibration, size);
    const cv::Matx34d& p = rectifier->ProjectionLeft();
    intrinsics.fx = p(0, 0);
    intrinsics.fy = p(1, 1);
    intrinsics.cx = p(0, 2);
    intrinsics.cy = p(1, 2);
    baseline = rectifier->Baseline();
  } else {
    const odo::KittiCalibration calib = openable::WithKey("Odometry_calibration", [&] {
      return odo::ReadKittiCalibration(c.odometry_calibration, c.odometry_calibration_scale);
    });
    intrinsics = calib.left;
    baseline = calib.baseline;
  }
  odo::StereoOdometryOptions o;
  o.matcher = Lower(c.odometry_matcher);
  o.wls_filter = c.odometry_wls_filter == 1;
  o.num_disparities = c.odometry_num_disparities;
  if (!c.odometry_features.empty()) o.features = c.odometry_features;
  o.max_features = c.odometry_max_features;
  o.ratio_test = c.odometry_ratio_test;
  o.max_depth = c.odometry_max_depth;
  if (c.odometry_ransac_threshold > 0) o.pnp_reprojection_px = c.odometry_ransac_threshold;
  if (c.odometry_min_inliers > 0) o.min_inliers = c.odometry_min_inliers;
  o.Check();
  odo::StereoOdometry odometry(intrinsics, baseline, o);
  report.scale = "stereo baseline " + Number(baseline) + " (metric)";
  progress.Begin("odometry", static_cast<std::int64_t>(left.size()), "stereo pairs");
  for (size_t i = 0; i < left.size(); ++i) {
    cv::Mat l = openable::WithKey("Images_path_left", [&] { return GrayOf(left[i]); });
    cv::Mat r = openable::WithKey("Images_path_right", [&] { return GrayOf(right[i]); });
    if (rectifier) {
      cv::Mat lr, rr;
      rectifier->Rectify(l, r, lr, rr);
      l = lr;
      r = rr;
    }
    const Eigen::Isometry3d pose = odometry.Step(l, r);
    record(odometry.last(), static_cast<int>(i), pose);
    progress.Update(static_cast<std::int64_t>(i) + 1);
  }
  progress.End();
  return t;
}

int Run(const openable::Config& c, bool quiet) {
  openable::CheckSnapsConfig(c);
  using Clock = std::chrono::steady_clock;
  auto say = [&](const std::string& line) {
    if (!quiet) std::cerr << "  " << line << "\n";
  };

  // Inputs: the ground truth first (the monocular odometry may take its scale from it).
  snaps::Trajectory truth;
  const bool evaluate = !c.snaps_ground_truth.empty();
  if (evaluate)
    truth = openable::WithKey("Snaps_ground_truth", [&] {
      return snaps::ReadTrajectory(
          c.snaps_ground_truth,
          snaps::ParseTrajectoryFormat(c.snaps_ground_truth_format, "Snaps_ground_truth_format"));
    });
  OdometryReport odometry_report;
  snaps::Trajectory computed;
  const bool odometry = !c.snaps_odometry.empty();
  if (odometry) {
    openable::ProgressReporter progress(std::cerr, !quiet, openable::IsTerminal(2));
    computed = ComputeOdometry(c, evaluate ? &truth : nullptr, progress, odometry_report);
  }
  const snaps::Trajectory input = odometry ? computed : openable::WithKey("Snaps_trajectory", [&] {
    return snaps::ReadTrajectory(
        c.snaps_trajectory,
        snaps::ParseTrajectoryFormat(c.snaps_trajectory_format, "Snaps_trajectory_format"),
        c.snaps_world_to_camera == 1);
  });
  std::vector<int> association;
  if (evaluate)
    association = snaps::AssociateWithTruth(input, truth, c.snaps_time_tolerance,
                                            "Snaps_ground_truth");
  const std::string trajectory_name = odometry ? Lower(c.snaps_odometry) + " odometry" : c.snaps_trajectory;

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
  } else if (source == "openable") {
    // An OpenABLE run on the same images, with the description keys of the configuration.
    openable::Config run = c;
    run.frame_mode = 0;
    run.camera_type = 0;
    run.images_path = !c.snaps_images.empty() ? c.snaps_images
                      : !c.images_path.empty() ? c.images_path
                                               : c.images_path_left;
    run.images_path_2.clear();
    run.txt_name.clear();
    run.npy_name.clear();
    run.png_name.clear();
    run.png_threshold_name.clear();
    run.matches_name.clear();
    run.threshold = -1;
    run.matrix_mode = 1;
    run.approximate_search = 0;
    run.ground_truth_type.clear();
    openable::ProgressReporter progress(std::cerr, !quiet, openable::IsTerminal(2));
    const openable::RunResult result = openable::ComputeRun(run, progress);
    snaps::MatrixLoopOptions m;
    m.threshold = c.snaps_matrix_threshold;
    m.exclusion = c.snaps_frame_distance;
    m.initial = c.initial_image;
    m.tolerance = c.snaps_keyframe_tolerance;
    loops = snaps::LoopsFromMatrix(result.normalized, input, m);
    say("OpenABLE: " + result.descriptor + ", L=" + std::to_string(c.image_sequences) + ", " +
        std::to_string(result.normalized.rows) + " frames, " + Number(result.timings.total_seconds) + " s");
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
            << "-" << input.frame_ids.back() << ") from " << (odometry ? trajectory_name : "\"" + trajectory_name + "\"") << "\n";
  snaps::LatencyStats odometry_stats;
  if (odometry) {
    odometry_stats = snaps::Summarize(odometry_report.seconds);
    std::cout << "  odometry: " << odometry_report.kind << ", scale from " << odometry_report.scale
              << "; " << odometry_report.failed << " failed steps (kept the previous motion)"
              << (odometry_report.failed ? ", first " + odometry_report.first_failure : std::string())
              << "\n  odometry per frame " << StatsLine(odometry_stats)
              << " (paper: 0.295 s per frame with loop closure)\n";
  }
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
  json << "{\n  \"trajectory\": \"" << trajectory_name << "\",\n  \"poses\": " << input.Size()
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
  if (odometry)
    json << ",\n  \"odometry\": {\"kind\": \"" << odometry_report.kind << "\", \"failed_steps\": "
         << odometry_report.failed << ", \"per_frame\": " << StatsJson(odometry_stats) << "}";
  json << "\n}\n";

  // Outputs, all or nothing.
  if (!c.snaps_output_name.empty()) {
    const std::string p = c.snaps_output_name;
    openable::OutputBatch batch;
    if (want_discounted)
      batch.Stage("Snaps_output_name", p + "_discounted.txt", snaps::EncodeTrajectory(discounted));
    if (want_graph)
      batch.Stage("Snaps_output_name", p + "_pose_graph.txt", snaps::EncodeTrajectory(graph));
    if (odometry) batch.Stage("Snaps_output_name", p + "_odometry.txt", snaps::EncodeTrajectory(input));
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
                   (odometry ? trajectory_name
                             : std::filesystem::path(c.snaps_trajectory).filename().string());
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
  openable::InstallInterruptCleanup("openable_snaps");
  openable::CommandLine cl;
  const std::string usage_error = openable::ParseCommandLine(argc, argv, "openable_snaps", cl);
  const int answered = openable::AnswerWithoutRunning(cl, usage_error, kUsage, "openable_snaps " + std::string(openable::kVersion));
  if (answered >= 0) return answered;
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
