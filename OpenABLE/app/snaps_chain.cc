#include "OpenABLE/app/snaps_chain.h"

#include <chrono>
#include <map>
#include <memory>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/output_batch.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/odometry/calibration.h"
#include "OpenABLE/odometry/mono_odometry.h"
#include "OpenABLE/odometry/stereo_odometry.h"
#include "OpenABLE/run/pipeline.h"
#include "OpenABLE/run/verify.h"
#include "OpenABLE/snaps/discounted.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/rectification.h"

namespace openable::snaps {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Frames [Initial_image, Final_image) of a folder, in natural order.
std::vector<std::string> FramesOf(const InputOptions& in, const std::string& folder,
                                  const std::string& key) {
  return WithKey(key, [&] {
    const std::vector<std::string> all = ListImages(folder, in.images_format);
    const int first = in.initial_image;
    const int last = in.final_image < 0 ? static_cast<int>(all.size())
                                        : std::min(in.final_image, static_cast<int>(all.size()));
    if (first >= last)
      throw InputError("folder " + Quoted(folder) + " holds " + std::to_string(all.size()) +
                       " images; Initial_image " + std::to_string(first) + " leaves none");
    return std::vector<std::string>(all.begin() + first, all.begin() + last);
  });
}

cv::Mat GrayOf(const std::string& path) { return ToGray8(ReadImageFile(path)); }

// The folder of the trajectory's frames: Snaps_images, or Images_path.
std::string ImagesOf(const Config& c) {
  return c.snaps.images.empty() ? c.input.images_path : c.snaps.images;
}
std::string ImagesKeyOf(const Config& c) {
  return c.snaps.images.empty() ? "Images_path" : "Snaps_images";
}

// Snaps_odometry: the trajectory of the frames computed from the images.
Trajectory ComputeOdometry(const Config& c, const Trajectory* truth, ProgressReporter& progress,
                           OdometryReport& report) {
  namespace odo = openable::odometry;
  const InputOptions& in = c.input;
  const odo::OdometryOptions& options = c.odometry;
  report.kind = EnumName(options.kind);
  Trajectory t;
  t.format = in.initial_image == 0 ? TrajectoryFormat::kKitti : TrajectoryFormat::kKittiWithId;
  auto record = [&](const odo::StepStats& stats, int i, const Eigen::Isometry3d& pose) {
    t.poses.push_back(pose);
    t.frame_ids.push_back(in.initial_image + i);
    report.seconds.push_back(stats.seconds);
    if (!stats.ok && report.failed++ == 0)
      report.first_failure = "frame " + std::to_string(in.initial_image + i) + ": " + stats.note;
  };
  if (options.kind == odo::OdometryKind::kMono) {
    const std::vector<std::string> frames = FramesOf(in, ImagesOf(c), ImagesKeyOf(c));
    const odo::KittiCalibration calib = WithKey("Odometry_calibration", [&] {
      return odo::ReadKittiCalibration(options.calibration, options.calibration_scale);
    });
    odo::MonoOdometry odometry(calib.left, options.Mono());
    progress.Begin("odometry", static_cast<std::int64_t>(frames.size()), "frames (mono)");
    const odo::StepScale scale = options.scale;
    report.scale =
        scale == odo::StepScale::kTruth
            ? "step lengths of the ground truth (a single camera cannot measure scale)"
        : scale == odo::StepScale::kStep
            ? "Odometry_step_length " + FormatNumber(options.step_length) + " m per frame"
            : "none: unit steps, arbitrary scale";
    std::map<long, int> truth_index;
    if (truth)
      for (int k = 0; k < truth->Size(); ++k)
        truth_index[truth->frame_ids[static_cast<size_t>(k)]] = k;
    for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
      double step = -1;
      if (scale == odo::StepScale::kStep) step = options.step_length;
      if (scale == odo::StepScale::kTruth && i > 0) {
        const long f = in.initial_image + i;
        const auto a = truth_index.find(f - 1), b = truth_index.find(f);
        if (a == truth_index.end() || b == truth_index.end())
          throw InputError("Odometry_scale: truth, but Snaps_ground_truth has no pose of frame " +
                           std::to_string(a == truth_index.end() ? f - 1 : f) +
                           "; expected the ground truth of every frame");
        step = (truth->poses[static_cast<size_t>(b->second)].translation() -
                truth->poses[static_cast<size_t>(a->second)].translation())
                   .norm();
      }
      const cv::Mat gray =
          WithKey("Snaps_images", [&] { return GrayOf(frames[static_cast<size_t>(i)]); });
      const Eigen::Isometry3d pose = odometry.Step(gray, step);
      record(odometry.last(), i, pose);
      progress.Update(i + 1);
    }
    progress.End();
    return t;
  }
  // Stereo.
  const std::vector<std::string> left = FramesOf(in, in.images_path_left, "Images_path_left");
  const std::vector<std::string> right = FramesOf(in, in.images_path_right, "Images_path_right");
  if (left.size() != right.size())
    throw InputError("Images_path_right: " + Quoted(in.images_path_right) + " holds " +
                     std::to_string(right.size()) + " images in the range but Images_path_left " +
                     std::to_string(left.size()) + "; expected one right image per left image");
  odo::Intrinsics intrinsics;
  double baseline = 0;
  std::unique_ptr<StereoRectifier> rectifier;
  if (!in.calibration_path.empty()) {
    const StereoCalibration calibration =
        WithKey("Calibration_path", [&] { return LoadStereoCalibration(in.calibration_path); });
    const cv::Size size = GrayOf(left.front()).size();
    CheckCalibrationFits(calibration, size, in.calibration_path);
    rectifier = std::make_unique<StereoRectifier>(calibration, size);
    const cv::Matx34d& p = rectifier->ProjectionLeft();
    intrinsics.fx = p(0, 0);
    intrinsics.fy = p(1, 1);
    intrinsics.cx = p(0, 2);
    intrinsics.cy = p(1, 2);
    baseline = rectifier->Baseline();
  } else {
    const odo::KittiCalibration calib = WithKey("Odometry_calibration", [&] {
      return odo::ReadKittiCalibration(options.calibration, options.calibration_scale);
    });
    intrinsics = calib.left;
    baseline = calib.baseline;
  }
  odo::StereoOdometry odometry(intrinsics, baseline, options.Stereo());
  report.scale = "stereo baseline " + FormatNumber(baseline) + " (metric)";
  progress.Begin("odometry", static_cast<std::int64_t>(left.size()), "stereo pairs");
  for (size_t i = 0; i < left.size(); ++i) {
    cv::Mat l = WithKey("Images_path_left", [&] { return GrayOf(left[i]); });
    cv::Mat r = WithKey("Images_path_right", [&] { return GrayOf(right[i]); });
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

// The loops of Snaps_loops matrix and openable: each frame's best earlier match.
MatrixLoopOptions MatrixLoops(const Config& c) {
  MatrixLoopOptions m;
  m.threshold = c.snaps.matrix_threshold;
  m.exclusion = c.snaps.search.frame_distance;
  m.initial = c.input.initial_image;
  m.tolerance = c.snaps.keyframe_tolerance;
  m.time_tolerance = c.snaps.time_tolerance;
  if (c.snaps.loops == LoopSource::kMatrix && !c.snaps.frame_times.empty())
    m.frame_times = ReadFrameTimes(c.snaps.frame_times, "Snaps_frame_times");
  return m;
}

// Snaps_loops openable: an OpenABLE run on the trajectory's images with the description and
// matching keys of the configuration, dense, one sequence, no output.
Config OpenableRunOf(const Config& c) {
  Config run = c;
  run.input.camera_type = CameraType::kMonocular;
  if (c.input.frame_mode == FrameMode::kBag && c.snaps.images.empty()) {
    // The bag's (left) image topic: its frames carry times, and a TUM trajectory takes the
    // loops by time.
    run.input.bag_topic_2.clear();
    run.input.bag_path_2.clear();
  } else {
    run.input.frame_mode = FrameMode::kImageFolders;
    run.input.images_path = !c.snaps.images.empty()        ? c.snaps.images
                            : !c.input.images_path.empty() ? c.input.images_path
                                                           : c.input.images_path_left;
  }
  run.input.images_path_2.clear();
  run.output.timestamps_name.clear();
  run.output.txt_name.clear();
  run.output.npy_name.clear();
  run.output.png_name.clear();
  run.output.png_threshold_name.clear();
  run.scale.matches_name.clear();
  run.matching.threshold = -1;
  run.scale.matrix_mode = MatrixMode::kDense;
  run.scale.approximate_search = false;
  run.evaluation.truth.type = GroundTruthType::kNone;
  // The candidates of a frame (verification) are the frames Snaps_frame_distance back, as for
  // the loops from the matrix.
  run.evaluation.protocol.exclusion = c.snaps.search.frame_distance;
  run.output.loops_name.clear();
  return run;
}

}  // namespace

ChainResult RunChain(const Config& c, ProgressReporter& progress,
                     const std::function<void(const std::string&)>& say_in) {
  CheckSnapsConfig(c);
  CheckOutputPrefix("Snaps_output_name", c.snaps.output_name);
  auto say = [&](const std::string& line) {
    if (say_in) say_in(line);
  };
  const SnapsOptions& s = c.snaps;
  ChainResult r;

  // Inputs: the ground truth first (the monocular odometry may take its scale from it).
  r.evaluated = !s.ground_truth.empty();
  if (r.evaluated)
    r.truth = WithKey("Snaps_ground_truth",
                      [&] { return ReadTrajectory(s.ground_truth, s.ground_truth_format); });
  r.computed = c.odometry.kind != odometry::OdometryKind::kNone;
  if (r.computed) {
    r.input = ComputeOdometry(c, r.evaluated ? &r.truth : nullptr, progress, r.odometry);
    r.trajectory_name = EnumName(c.odometry.kind) + " odometry";
  } else {
    r.input = WithKey("Snaps_trajectory", [&] {
      return ReadTrajectory(s.trajectory, s.trajectory_format, s.world_to_camera);
    });
    r.trajectory_name = s.trajectory;
  }
  if (r.evaluated)
    r.association = AssociateWithTruth(r.input, r.truth, s.time_tolerance, "Snaps_ground_truth");

  SearchOptions search = s.search;
  search.vertical =
      s.axes == GroundPlane::kXy ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();

  // Loops.
  auto t = Clock::now();
  switch (s.loops) {
    case LoopSource::kPairs:
      try {
        r.loops = WithKey("Snaps_loops_file", [&] {
          return LoopsFromCsv(s.loops_file, r.input, s.keyframe_tolerance, nullptr,
                              s.drop_outside ? &r.pairs.outside : nullptr, &r.pairs);
        });
      } catch (const InputError& e) {
        const std::string m = e.what();
        if (m.find("outside the trajectory") == std::string::npos) throw;
        throw InputError(m + " (Snaps_drop_outside 1 drops such pairs)");
      }
      if (s.middle_of_runs) r.loops = MiddleOfRuns(r.loops, r.input);
      break;
    case LoopSource::kMatrix: {
      const MatrixLoopOptions by = MatrixLoops(c);
      r.loops_by_time = !by.frame_times.empty() && !r.input.timestamps.empty();
      r.loops = WithKey("Snaps_loops_file",
                        [&] { return LoopsFromMatrix(s.loops_file, r.input, by, &r.pairs); });
      break;
    }
    case LoopSource::kOpenable: {
      const Config openable = OpenableRunOf(c);
      const RunResult run = ComputeRun(openable, progress);
      if (c.verification.enabled) {
        // The verified answers are the loops: no threshold on M'.
        const RunVerification verification = VerifyRun(openable, run, progress);
        std::vector<FrameMatch> answers;
        for (const QueryVerification& q : verification.queries)
          if (q.answer >= 0)
            answers.push_back(
                {q.query, q.candidates[q.answer].reference, q.candidates[q.answer].distance});
        MatrixLoopOptions by = MatrixLoops(c);
        by.frame_times = run.traversals.front().times;
        r.loops_by_time = !by.frame_times.empty() && !r.input.timestamps.empty();
        r.loops = LoopsFromMatches(answers, r.input, by, &r.pairs);
        r.verified_loops = true;
        say("OpenABLE: " + run.descriptor + ", L=" + std::to_string(c.matching.sequence_length) +
            ", " + std::to_string(run.normalized.rows) + " frames, " +
            std::to_string(verification.pairs) + " candidates checked, " +
            std::to_string(answers.size()) + " verified loops, " +
            FormatNumber(run.timings.total_seconds + verification.seconds) + " s");
        break;
      }
      MatrixLoopOptions by = MatrixLoops(c);
      by.frame_times = run.traversals.front().times;  // empty unless the frames carry times
      r.loops_by_time = !by.frame_times.empty() && !r.input.timestamps.empty();
      r.loops = LoopsFromMatrix(run.normalized, r.input, by, &r.pairs);
      say("OpenABLE: " + run.descriptor + ", L=" + std::to_string(c.matching.sequence_length) +
          ", " + std::to_string(run.normalized.rows) + " frames, " +
          FormatNumber(run.timings.total_seconds) + " s");
      break;
    }
    case LoopSource::kSearch:
      say("searching loops on thumbnails of " + ImagesOf(c) + " (" +
          std::to_string(r.input.Size()) + " poses)");
      r.searched = WithKey(ImagesKeyOf(c), [&] {
        return SearchLoopsInImages(ImagesOf(c), c.input.images_format, c.input.initial_image,
                                   r.input, search);
      });
      r.loops = r.searched.loops;
      break;
  }
  r.loop_seconds = Seconds(t);
  say(std::to_string(r.loops.size()) + " loop pairs (" + EnumName(s.loops) + ")" +
      (r.pairs.associated == 0 ? std::string()
       : r.loops_by_time       ? ", " + std::to_string(r.pairs.associated) +
                               " pairs associated by time to the nearest pose within " +
                               FormatNumber(s.time_tolerance) + " s"
                         : ", " + std::to_string(r.pairs.associated) +
                               " pairs associated to the nearest pose within +-" +
                               std::to_string(s.keyframe_tolerance) +
                               (s.keyframe_tolerance == 1 ? " frame" : " frames")) +
      (r.pairs.dropped > 0 ? ", " + std::to_string(r.pairs.dropped) +
                                 " pairs with a frame that is not a pose dropped"
                           : std::string()) +
      (r.pairs.outside > 0
           ? ", " + std::to_string(r.pairs.outside) + " pairs outside the trajectory dropped"
           : std::string()));

  // Corrections.
  r.discounted_ran = s.corrector != Corrector::kPoseGraph;
  r.graph_ran = s.corrector != Corrector::kDiscounted;
  if (r.discounted_ran) {
    t = Clock::now();
    if (s.loops == LoopSource::kSearch) {
      r.discounted = r.searched.corrected;
      r.closed = r.loops;
    } else {
      r.discounted = CorrectDiscounted(r.input, r.loops, search.discount);
      r.closed = ClosedLoops(r.loops, search.discount.pause);
    }
    r.discounted_seconds = Seconds(t);
  }
  if (r.graph_ran) {
    say("pose graph: " + std::to_string(r.input.Size()) + " poses, " +
        std::to_string(r.loops.size()) + " loop edges");
    r.graph = CorrectPoseGraph(r.input, r.loops, s.pose_graph, &r.graph_report);
  }

  // Errors against the ground truth.
  if (r.evaluated) {
    auto add = [&](const char* name, const Trajectory& trajectory) {
      r.errors.push_back({name, AbsoluteTrajectoryError(trajectory, r.truth, r.association, false),
                          AbsoluteTrajectoryError(trajectory, r.truth, r.association, true)});
    };
    add("input", r.input);
    if (r.discounted_ran) add("discounted", r.discounted);
    if (r.graph_ran) add("pose_graph", r.graph);
  }
  return r;
}

}  // namespace openable::snaps
