#include "OpenABLE/run/pipeline.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <future>
#include <stdexcept>
#include <filesystem>

#include "OpenABLE/base/error.h"
#include "OpenABLE/run/describe.h"
#include "OpenABLE/run/descriptor_cache.h"
#include "OpenABLE/run/evaluate.h"
#include "OpenABLE/run/exports.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/stereo_source.h"
#include "descriptors/registry.h"
#include "matching/matrix.h"
#include "matching/normalize.h"
#include "matching/panorama.h"
#include "matching/sequence.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}


enum class SourceKind { kFolder, kVideo, kStereo };

struct SourceSpec {
  std::string key, path;
  SourceKind kind;
};

std::vector<SourceSpec> Sources(const InputOptions& c) {
  // Stereo (Camera_type 1): one pair of folders; CheckConfig rejects videos and Images_path_2.
  if (c.camera_type == CameraType::kStereo)
    return {{"Images_path_left", c.images_path_left, SourceKind::kStereo}};
  switch (c.frame_mode) {
    case FrameMode::kImageFolders: {
      std::vector<SourceSpec> s = {{"Images_path", c.images_path, SourceKind::kFolder}};
      if (!c.images_path_2.empty())
        s.push_back({"Images_path_2", c.images_path_2, SourceKind::kFolder});
      return s;
    }
    case FrameMode::kVideo:
      return {{"Video_path_1", c.video_path_1, SourceKind::kVideo}};
    case FrameMode::kTwoVideos:
      break;
  }
  return {{"Video_path_1", c.video_path_1, SourceKind::kVideo},
          {"Video_path_2", c.video_path_2, SourceKind::kVideo}};
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * page : 8.0 * (1 << 30);
}

bool HasDisplay() {
  return std::getenv("DISPLAY") != nullptr || std::getenv("WAYLAND_DISPLAY") != nullptr;
}

}  // namespace

RunResult ComputeRun(const Config& config, ProgressReporter& progress) {
  CheckConfig(config);
  const auto run_start = Clock::now();
  RunResult result;

  const InputOptions& input = config.input;
  const MatchingOptions& matching = config.matching;
  const auto descriptor = CreateDescriptor(config.descriptor);
  const bool panoramic = input.camera_type == CameraType::kPanoramic;
  const int strips = panoramic ? config.description.panoramas : 1;
  const PanoramaMatching panorama_matching = matching.panorama_matching;
  const FrameDescriber describer(*descriptor, config.description.type, config.description.grid_x,
                                 config.description.grid_y, strips);
  // Eq. 7 replaces Alpha when the three peak responses are given.
  const bool lambdas = config.preprocess.lambda_red > 0;
  const double alpha = config.preprocess.Alpha();
  {
    char text[200];
    result.camera = panoramic ? "panoramic, " + std::to_string(strips) + " sub-panoramas, " +
                                    EnumName(panorama_matching) + " matching"
                  : input.camera_type == CameraType::kStereo
                      ? std::string("stereo, rectified") +
                            (descriptor->Channels() == 2 ? ", SGBM disparity" : ", left image")
                      : "monocular";
    if (config.preprocess.illumination_invariance) {
      std::snprintf(text, sizeof text, ", illumination invariant (Eq. 6, alpha %.4f%s)", alpha,
                    lambdas ? " from Eq. 7" : "");
      result.camera += text;
    } else {
      result.camera += ", grey";
    }
  }
  result.descriptor = descriptor->Name();
  result.row_width = describer.RowWidth();
  result.binary = descriptor->Kind() == DescriptorKind::kBinary;

  // Open every source first, so that a bad second folder is reported before any work.
  std::vector<std::unique_ptr<FrameSource>> sources;
  const std::vector<SourceSpec> specs = Sources(input);
  for (const auto& spec : specs) {
    if (spec.kind == SourceKind::kStereo) {
      // The stereo source's messages name their keys (Images_path_left, Images_path_right,
      // Calibration_path) themselves.
      StereoSourceOptions stereo_options;
      stereo_options.compute_disparity = describer.Channels() == 2;  // only D-LDB reads it
      const StereoCalibration calibration = WithKey(
          "Calibration_path", [&] { return LoadStereoCalibration(input.calibration_path); });
      sources.push_back(OpenStereoFolders(input.images_path_left, input.images_path_right,
                                          input.images_format, input.initial_image,
                                          input.final_image, calibration, stereo_options));
      continue;
    }
    sources.push_back(WithKey(spec.key, [&] {
      return spec.kind == SourceKind::kVideo
                 ? OpenVideo(spec.path, input.initial_image, input.final_image)
                 : OpenImageFolder(spec.path, input.images_format, input.initial_image,
                                   input.final_image);
    }));
  }

  // Dense or bounded (Matrix_mode), said in one line, decided before any work from the frame
  // counts of the sources (skipped frames can only make the matrix smaller).
  std::int64_t planned = 0;
  for (const auto& source : sources) planned += source->Size();
  const ScaleOptions& scale = config.scale;
  const SequenceDirection direction = matching.direction;
  const double gib = 1024.0 * 1024.0 * 1024.0;
  const double dense_bytes = static_cast<double>(planned) * planned * 4.0 *
                             (direction == SequenceDirection::kBoth ? 2.0 : 1.0);
  const double limit_bytes = scale.memory_limit > 0 ? scale.memory_limit * gib
                                                     : 0.75 * PhysicalMemoryBytes();
  char sizes[160];
  std::snprintf(sizes, sizeof sizes, "the %lldx%lld matrix needs %.2f GiB, Memory_limit %.2f GiB%s",
                static_cast<long long>(planned), static_cast<long long>(planned), dense_bytes / gib,
                limit_bytes / gib, scale.memory_limit > 0 ? "" : " (3/4 of the RAM)");
  if (scale.approximate_search) {
    result.bounded = true;
    result.mode_reason = "bounded (Approximate_search 1)";
  } else if (scale.matrix_mode == MatrixMode::kBounded) {
    result.bounded = true;
    result.mode_reason = "bounded (Matrix_mode 2)";
  } else if (scale.matrix_mode == MatrixMode::kDense) {
    result.mode_reason = std::string("dense (Matrix_mode 1; ") + sizes + ")";
  } else {
    result.bounded = dense_bytes > limit_bytes;
    result.mode_reason = std::string(result.bounded ? "bounded" : "dense") + " (Matrix_mode 0: " +
                         sizes + ")";
  }
  if (result.bounded && scale.matches_name.empty())
    throw InputError("Matches_name: empty, but the run is " + result.mode_reason +
                     " and keeps only matches; expected a .npy or .csv path (or a larger "
                     "Memory_limit for the dense matrix)");

  if (result.bounded && panoramic && panorama_matching != PanoramaMatching::kAligned)
    throw InputError(std::string("Panorama_matching: ") +
                     std::to_string(static_cast<int>(panorama_matching)) +
                     " (" + EnumName(panorama_matching) + ") needs the dense "
                     "matrix, but the run is " + result.mode_reason +
                     "; expected Matrix_mode 1 (or 0 with a larger Memory_limit) or "
                     "Panorama_matching 0");

  DescribeOptions options;
  options.threads = matching.threads;
  options.skip_unreadable = input.skip_unreadable;
  options.show_images = config.output.show_images && HasDisplay();
  options.preprocess = config.preprocess;

  // Descriptor cache: image folders only (a video frame or a stereo pair has no one file).
  std::unique_ptr<DescriptorCache> cache;
  if (!scale.descriptor_cache.empty()) {
    if (specs.front().kind != SourceKind::kFolder) {
      result.notes.push_back("Descriptor_cache: not used: the cache keeps rows of image "
                             "files (Frame_mode 0, Camera_type 0 or 2), not of videos or "
                             "stereo pairs");
    } else if (options.show_images) {
      result.notes.push_back("Descriptor_cache: not used with Show_images 1");
    } else if (options.preprocess.noise.Any()) {
      // The noise of a frame depends on its position in the run, not only on its bytes.
      result.notes.push_back("Descriptor_cache: not used with Noise_* (a frame's noise depends "
                             "on its position in the run, not only on the image)");
    } else {
      cache = DescriptorCache::Open(
          scale.descriptor_cache,
          DescriptionSettingsText(config, descriptor->Name(), describer.RowWidth(),
                                  describer.RowType()),
          describer.RowWidth(), describer.RowType(), result.warnings);
      options.cache = cache.get();
    }
  }

  // Describe.
  auto t = Clock::now();
  std::vector<cv::Mat> blocks;
  int row = 0;
  for (size_t s = 0; s < sources.size(); ++s) {
    const bool stereo = specs[s].kind == SourceKind::kStereo;
    options.key = stereo ? "" : specs[s].key;  // stereo read errors name their own key
    options.noise_stream = static_cast<int>(s);  // each traversal its own noise
    progress.Begin("describing", sources[s]->Size(),
                   stereo ? "stereo pairs (rectify" +
                                std::string(describer.Channels() == 2 ? ", SGBM" : "") + ", " +
                                result.descriptor + ")"
                          : "frames of " + specs[s].key);
    DescribedSequence seq = DescribeSequence(*sources[s], describer, options,
                                             [&](int done, int) { progress.Update(done); });
    progress.End();
    Traversal tr;
    tr.key = specs[s].key;
    tr.path = specs[s].path;
    tr.first_row = row;
    tr.frames = seq.rows.rows;
    tr.skipped = seq.skipped;
    tr.frame_size = seq.frame_size;
    for (int i : seq.kept) tr.names.push_back(sources[s]->FrameName(i));
    row += tr.frames;
    result.timings.frames += sources[s]->Size();
    result.traversals.push_back(std::move(tr));
    blocks.push_back(seq.rows);
  }
  result.timings.describe_seconds = SecondsSince(t);
  if (cache) {
    result.cache = std::to_string(cache->Hits()) + " of " +
                   std::to_string(result.timings.frames) + " frames from the cache, " +
                   std::to_string(cache->Stored()) + " added (\"" + cache->Path() + "\")";
    const std::string problem = cache->WriteProblem();
    if (!problem.empty()) result.warnings.push_back(problem);
  }
  cv::Mat descriptors;
  cv::vconcat(blocks, descriptors);

  std::vector<int> starts;
  for (const auto& tr : result.traversals) starts.push_back(tr.first_row);
  const std::int64_t n = descriptors.rows;
  const MatchBlock block = BlockOf(starts, static_cast<int>(n));
  KeepRules rules = scale.keep;
  rules.exclusion = config.evaluation.protocol.exclusion;
  rules.one_traversal = block.one_traversal;

  if (result.bounded) {
    for (const char* key : {"Txt_name", "Npy_name", "Png_name", "Png_threshold_name"}) {
      const OutputOptions& o = config.output;
      const std::string& v = std::string(key) == "Txt_name"  ? o.txt_name
                             : std::string(key) == "Npy_name" ? o.npy_name
                             : std::string(key) == "Png_name" ? o.png_name
                                                              : o.png_threshold_name;
      if (!v.empty())
        result.notes.push_back(std::string(key) + ": not written: the run is bounded and "
                               "keeps no dense matrix (see Matches_name)");
    }
    t = Clock::now();
    result.timings.pairs =
        static_cast<std::int64_t>(block.query_count) * block.reference_count;
    progress.Begin("matching", block.query_count, "queries (bounded: tiles of rows)");
    BoundedOptions options;
    options.sequence_length = matching.sequence_length;
    options.direction = direction;
    options.threads = matching.threads;
    if (scale.approximate_search) {
      result.matches = ApproximateMatches(descriptors, block, rules, options,
                                          scale.approximate_checks, result.max_distance);
    } else {
      result.matches = BoundedMatches(descriptors, block, rules, options, result.max_distance,
                                      [&](int done, int) { progress.Update(done); });
    }
    progress.End();
    result.timings.match_seconds = SecondsSince(t);
    result.timings.total_seconds = SecondsSince(run_start);
    return result;
  }

  // Dense: every frame against every frame of the concatenated traversals, as the original.
  t = Clock::now();
  result.timings.pairs = n * (n - 1) / 2;
  const bool cross = panoramic && panorama_matching != PanoramaMatching::kAligned;
  progress.Begin("matching", n * n * (cross ? strips * strips : 1),
                 cross ? "cells of sub-panorama pairs" : "cells");
  const PairProgress on_pairs = [&](std::int64_t done, std::int64_t) { progress.Update(done); };
  cv::Mat1f distances =
      PairwiseDistances(descriptors, strips, panorama_matching, matching.threads, on_pairs);
  progress.End();
  result.timings.match_seconds = SecondsSince(t);

  // Sequences, Eq. 5, Eq. 9.
  t = Clock::now();
  SequenceDistancesInPlace(distances, matching.sequence_length, starts, starts, direction,
                           matching.threads);
  result.normalized = distances;
  distances.release();
  result.max_distance = NormalizeByMax(result.normalized);
  if (matching.threshold >= 0.0)
    result.thresholded =
        ThresholdMatrix(result.normalized, static_cast<float>(matching.threshold));
  if (!scale.matches_name.empty())
    result.matches = MatchesFromMatrix(result.normalized, block, rules);
  result.timings.sequence_seconds = SecondsSince(t);
  result.timings.total_seconds = SecondsSince(run_start);
  return result;
}

EvaluationLayout LayoutOf(const RunResult& result) {
  if (result.traversals.size() == 2)
    return EvaluationLayout::TwoTraversals(result.traversals[0].frames,
                                           result.traversals[1].frames);
  if (result.traversals.size() != 1)
    throw std::logic_error("LayoutOf: a run has one or two traversals");
  return EvaluationLayout::LoopClosure(result.normalized.rows);
}

std::string ThresholdPngPath(const Config& config) {
  return config.output.ThresholdPngPath(config.matching.threshold >= 0.0);
}

std::vector<std::string> WriteOutputs(const Config& config, RunResult& result,
                                      const Evaluation* evaluation) {
  const auto t = Clock::now();
  // The encodings are independent; the two PNG images dominate (OpenCV's PNG encoder is
  // single-threaded), so every output is encoded on its own thread, then staged in order.
  struct Pending {
    std::string key, path;
    std::future<std::string> bytes;
  };
  std::vector<Pending> pending;
  auto encode = [&](const std::string& key, const std::string& path, auto make) {
    pending.push_back({key, path, std::async(std::launch::async, make)});
  };
  const OutputOptions& out = config.output;
  const bool dense = !result.bounded;  // bounded runs keep no matrix: only Matches_name
  if (dense && !out.txt_name.empty())
    encode("Txt_name", out.txt_name, [&] {
      return EncodeText(result.thresholded.empty() ? cv::Mat(result.normalized)
                                                   : cv::Mat(result.thresholded));
    });
  if (dense && !out.png_name.empty())
    encode("Png_name", out.png_name,
           [&] { return EncodePng(ColorizeMatrix(result.normalized, out.matrix_color)); });
  const std::string threshold_png = ThresholdPngPath(config);
  if (dense && !threshold_png.empty()) {
    encode(out.png_threshold_name.empty() ? "Png_name" : "Png_threshold_name", threshold_png,
           [&] {
             cv::Mat1f binary;
             result.thresholded.convertTo(binary, CV_32F);
             return EncodePng(ColorizeMatrix(binary, out.matrix_color));
           });
  }
  OutputBatch batch;
  if (dense && !out.npy_name.empty()) {
    // Written from the matrix itself while the other outputs are being encoded.
    const std::string header = NpyHeader(result.normalized.rows, result.normalized.cols);
    std::vector<std::string_view> parts = {header};
    for (int i = 0; i < result.normalized.rows; ++i)
      parts.emplace_back(reinterpret_cast<const char*>(result.normalized.ptr<float>(i)),
                         result.normalized.cols * sizeof(float));
    batch.Stage("Npy_name", out.npy_name, parts);
  }
  for (Pending& p : pending) batch.Stage(p.key, p.path, p.bytes.get());
  const std::string& matches = config.scale.matches_name;
  if (!matches.empty()) {
    const bool csv =
        matches.size() >= 4 && matches.compare(matches.size() - 4, 4, ".csv") == 0;
    batch.Stage("Matches_name", matches, EncodeMatches(result.matches, csv));
  }
  if (evaluation != nullptr && !config.evaluation.name.empty())
    StageEvaluation(batch, "Evaluation_name", config.evaluation.name, *evaluation,
                    {&result.normalized});
  const std::vector<std::string> paths = batch.Paths();
  batch.Commit();
  const double seconds = SecondsSince(t);
  result.timings.export_seconds += seconds;
  result.timings.total_seconds += seconds;
  return paths;
}

}  // namespace openable
