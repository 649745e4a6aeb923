#include "OpenABLE/run/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <functional>
#include <future>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <filesystem>

#include "OpenABLE/base/error.h"
#include "OpenABLE/cluster/distributed.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/run/descriptor_cache.h"
#include "OpenABLE/run/verify.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/stereo_source.h"
#include "descriptors/registry.h"
#include "matching/contrast.h"
#include "matching/matrix.h"
#include "matching/normalize.h"
#include "matching/panorama.h"
#include "matching/sequence.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;


enum class SourceKind { kFolder, kVideo, kStereo, kBag, kStereoBag };

struct SourceSpec {
  std::string key, path;
  SourceKind kind;
  std::string topic_key = {}, topic = {};  // bags: the topic and its key
};

std::vector<SourceSpec> Sources(const InputOptions& c) {
  // Stereo (Camera_type 1): one pair of folders or bag topics; CheckConfig rejects videos and
  // second traversals.
  if (c.camera_type == CameraType::kStereo && c.frame_mode == FrameMode::kBag)
    return {{"Bag_path", c.bag_path, SourceKind::kStereoBag, "Bag_topic", c.bag_topic}};
  if (c.camera_type == CameraType::kStereo)
    return {{"Images_path_left", c.images_path_left, SourceKind::kStereo}};
  switch (c.frame_mode) {
    case FrameMode::kBag: {
      std::vector<SourceSpec> s = {
          {"Bag_path", c.bag_path, SourceKind::kBag, "Bag_topic", c.bag_topic}};
      if (!c.bag_topic_2.empty())
        s.push_back({c.bag_path_2.empty() ? "Bag_path" : "Bag_path_2",
                     c.bag_path_2.empty() ? c.bag_path : c.bag_path_2, SourceKind::kBag,
                     "Bag_topic_2", c.bag_topic_2});
      return s;
    }
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

// One traversal's frames as they are stored (a stereo camera's left images, unrectified).
// Bag errors name their own keys; folder and video errors get the key of the source.
std::unique_ptr<FrameSource> OpenStoredFrames(const SourceSpec& spec, const InputOptions& input) {
  switch (spec.kind) {
    case SourceKind::kBag:
    case SourceKind::kStereoBag:
      return OpenBag(spec.path, spec.topic, input.initial_image, input.final_image, spec.key,
                     spec.topic_key);
    case SourceKind::kVideo:
      return WithKey(spec.key,
                     [&] { return OpenVideo(spec.path, input.initial_image, input.final_image); });
    case SourceKind::kStereo:
    case SourceKind::kFolder:
      break;
  }
  return WithKey(spec.key, [&] {
    return OpenImageFolder(spec.path, input.images_format, input.initial_image,
                           input.final_image);
  });
}

}  // namespace

std::vector<std::unique_ptr<FrameSource>> OpenFramesToShow(const InputOptions& input) {
  std::vector<std::unique_ptr<FrameSource>> sources;
  for (const SourceSpec& spec : Sources(input)) sources.push_back(OpenStoredFrames(spec, input));
  return sources;
}

namespace {

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * page : 8.0 * (1 << 30);
}

bool HasDisplay() {
  return std::getenv("DISPLAY") != nullptr || std::getenv("WAYLAND_DISPLAY") != nullptr;
}

Metric MetricOf(const Descriptor& d) {
  switch (d.Distance()) {
    case DistanceKind::kHamming: return Metric::kHamming;
    case DistanceKind::kL2: return Metric::kL2;
    case DistanceKind::kL1: break;
  }
  return Metric::kL1;
}

const char* DistanceText(Metric m) {
  switch (m) {
    case Metric::kHamming: return "Hamming";
    case Metric::kL2: return "L2";
    case Metric::kL1: break;
  }
  return "L1";
}

// The frames of every source described with one descriptor.
struct Described {
  cv::Mat rows;                      // the traversals' rows, concatenated
  std::vector<Traversal> traversals;
  std::string cache;
  std::vector<std::string> warnings, notes;
  double seconds = 0;
  int frames = 0;
};

// Describes every source with `describer`; `config` is the run's with Image_descriptor the one
// descriptor described (it keys the descriptor cache).
Described DescribeSources(const Config& config, const FrameDescriber& describer,
                          const std::string& name, const std::vector<SourceSpec>& specs,
                          const std::vector<std::unique_ptr<FrameSource>>& sources,
                          ProgressReporter& progress) {
  const InputOptions& input = config.input;
  Described out;
  DescribeOptions options;
  options.threads = config.matching.threads;
  options.skip_unreadable = input.skip_unreadable;
  options.show_images = config.output.show_images && HasDisplay();
  options.preprocess = config.preprocess;

  // Descriptor cache: image folders only (a video frame or a stereo pair has no one file).
  std::unique_ptr<DescriptorCache> cache;
  const ScaleOptions& scale = config.scale;
  if (!scale.descriptor_cache.empty()) {
    if (specs.front().kind != SourceKind::kFolder) {
      out.notes.push_back("Descriptor_cache: not used: the cache keeps rows of image "
                          "files (Frame_mode 0, Camera_type 0 or 2), not of videos, bags "
                          "or stereo pairs");
    } else if (options.show_images) {
      out.notes.push_back("Descriptor_cache: not used with Show_images 1");
    } else if (options.preprocess.noise.Any()) {
      // The noise of a frame depends on its position in the run, not only on its bytes.
      out.notes.push_back("Descriptor_cache: not used with Noise_* (a frame's noise depends "
                          "on its position in the run, not only on the image)");
    } else {
      // Spread over processes, each process keeps its own cache (its share of the frames) in
      // a folder of the cache named after it.
      const Cluster& cluster = Cluster::Get();
      cache = DescriptorCache::Open(
          cluster.Distributed() ? scale.descriptor_cache + "/process-" +
                                      std::to_string(cluster.Rank()) + "-of-" +
                                      std::to_string(cluster.Size())
                                : scale.descriptor_cache,
          DescriptionSettingsText(config, name, describer.RowWidth(), describer.RowType()),
          describer.RowWidth(), describer.RowType(), out.warnings);
      options.cache = cache.get();
    }
  }

  const auto t = Clock::now();
  std::vector<cv::Mat> blocks;
  int row = 0;
  for (size_t s = 0; s < sources.size(); ++s) {
    const bool stereo =
        specs[s].kind == SourceKind::kStereo || specs[s].kind == SourceKind::kStereoBag;
    options.key = stereo ? "" : specs[s].key;  // stereo read errors name their own key
    options.noise_stream = static_cast<int>(s);  // each traversal its own noise
    // Spread over processes: process 0's progress counts its share.
    const auto [share_first, share_last] = Cluster::Get().Share(sources[s]->Size());
    progress.Begin("describing", share_last - share_first,
                   stereo ? "stereo pairs (rectify" +
                                std::string(describer.Channels() == 2 ? ", SGBM" : "") + ", " +
                                name + ")"
                          : "frames of " + specs[s].key + " (" + name + ")");
    DescribedSequence seq = DescribeShared(Cluster::Get(), *sources[s], describer, options,
                                           [&](int done, int) { progress.Update(done); });
    progress.End();
    Traversal tr;
    tr.key = specs[s].key;
    tr.path = specs[s].path;
    tr.first_row = row;
    tr.frames = seq.rows.rows;
    tr.skipped = seq.skipped;
    tr.frame_size = seq.frame_size;
    for (int i : seq.kept) {
      tr.names.push_back(sources[s]->FrameName(i));
      tr.times.push_back(sources[s]->Timestamp(i));
    }
    if (std::any_of(tr.times.begin(), tr.times.end(), [](double t) { return std::isnan(t); }))
      tr.times.clear();  // a source without times
    row += tr.frames;
    out.frames += sources[s]->Size();
    out.traversals.push_back(std::move(tr));
    blocks.push_back(seq.rows);
  }
  out.seconds = SecondsSince(t);
  if (cache) {
    out.cache = std::to_string(cache->Hits()) + " of " +
                std::to_string(out.frames) + " frames from the cache, " +
                std::to_string(cache->Stored()) + " added (\"" + cache->Path() + "\")";
    const std::string problem = cache->WriteProblem();
    if (!problem.empty()) out.warnings.push_back(problem);
  }
  cv::vconcat(blocks, out.rows);
  return out;
}

// The best matches a run answered and accepted (Match_threshold, Match_consistency), from its
// matches of rank 1.
void CountAccepted(RunResult& result, const MatchingOptions& matching,
                   const std::vector<Match>& matches) {
  int queries = 0;
  result.answered_queries = 0;
  for (const Match& m : matches)
    if (m.rank == 1) {
      ++result.answered_queries;
      queries = std::max(queries, m.query + 1);
    }
  const AgreementOptions agreement = AgreementOf(matching);
  const std::vector<std::uint8_t> accepted =
      AcceptedMatches(matches, queries, matching.match_threshold,
                      matching.match_consistency > 0 ? &agreement : nullptr);
  result.accepted_queries = static_cast<int>(std::count(accepted.begin(), accepted.end(), 1));
}

// Adds `more` to `all`, each line once.
void AddLines(std::vector<std::string>& all, const std::vector<std::string>& more) {
  for (const std::string& line : more)
    if (std::find(all.begin(), all.end(), line) == all.end()) all.push_back(line);
}

}  // namespace

const SingleFrame* SingleFrameStore::Find(const std::string& key) const {
  for (const auto& [k, frame] : kept_)
    if (k == key) return frame.get();
  return nullptr;
}

const SingleFrame& SingleFrameStore::Keep(const std::string& key, SingleFrame frame) {
  kept_.emplace_back(key, std::make_unique<SingleFrame>(std::move(frame)));
  return *kept_.back().second;
}

std::string SingleFrameKey(const Config& config, const std::string& name) {
  // Everything that can change a frame's row or a pair's distance stays; what acts after the
  // single-frame matrix (sequences, scores, fusion, outputs, evaluation, verification, tools)
  // is reset.
  Config c = config;
  c.descriptor.name = name;
  const PanoramaMatching panorama = c.matching.panorama_matching;
  c.matching = MatchingOptions();
  c.matching.panorama_matching = panorama;
  c.output = OutputOptions();
  c.scale = ScaleOptions();
  c.automatic = AutoOptions();
  c.evaluation = EvaluationConfig();
  c.snaps = snaps::SnapsOptions();
  c.odometry = odometry::OdometryOptions();
  c.verification = VerificationOptions();
  return FormatConfig(c);
}

namespace {

// Where ComputeOrCheckRun stops: after its checks (before the first frame is described, once
// the configuration, the descriptors, the sources and the mode are checked), once the store
// holds the run's single-frame matrices, or at the end of the run.
enum class StopAfter { kChecks, kSingleFrames, kRun };

// Steps 2 and 3 of a dense run (docs/architecture.md): the single-frame matrices of several
// descriptors each divided by its largest value (`largest_of` gives it over every process) and
// summed with their weights, then contrast enhancement. One matrix is used as it is, copied
// when `copy`.
cv::Mat1f FusedSingleFrame(const std::vector<const cv::Mat1f*>& singles,
                           const std::vector<double>& weights, const MatchingOptions& matching,
                           const std::vector<int>& starts, bool copy,
                           const std::function<double(double)>& largest_of) {
  cv::Mat1f distances;
  if (singles.size() == 1) {
    distances = copy ? singles.front()->clone() : *singles.front();
  } else {
    distances = cv::Mat1f::zeros(singles.front()->size());
    for (size_t k = 0; k < singles.size(); ++k) {
      double largest = 0;
      if (!singles[k]->empty()) cv::minMaxLoc(*singles[k], nullptr, &largest);
      largest = largest_of(largest);
      // A descriptor whose frames are all alike (largest 0) adds nothing.
      if (largest > 0) cv::scaleAdd(*singles[k], weights[k] / largest, distances, distances);
    }
  }
  if (matching.contrast_enhancement)
    EnhanceContrast(distances, matching.contrast_window, starts, matching.threads);
  return distances;
}

RunResult ComputeOrCheckRun(const Config& config, ProgressReporter& progress,
                            SingleFrameStore* store, StopAfter stop) {
  CheckConfig(config);
  const auto run_start = Clock::now();
  RunResult result;

  const InputOptions& input = config.input;
  const MatchingOptions& matching = config.matching;
  // The descriptors (several: a fusion of their matrices), each created (and so checked) now.
  const std::vector<std::string> names = DescriptorList(config.descriptor.name);
  const bool fused = names.size() > 1;
  std::vector<std::unique_ptr<Descriptor>> descriptors;
  for (const std::string& name : names) {
    DescriptorOptions o = config.descriptor;
    o.name = name;
    descriptors.push_back(CreateDescriptor(o));
    if (fused && descriptors.back()->Channels() != 1)
      throw InputError("Image_descriptor: \"" + config.descriptor.name + "\" fuses " + name +
                       ", whose stereo frames carry a disparity channel the others do not "
                       "read; expected " + name + " alone");
    result.descriptors.push_back({name, 0, MetricOf(*descriptors.back())});
  }
  result.descriptor = names.front();
  for (size_t k = 1; k < names.size(); ++k) result.descriptor += "+" + names[k];
  if (fused) {
    result.fusion_weights = matching.FusionWeights(static_cast<int>(names.size()));
    if (matching.fusion_weights.empty()) {
      for (const RunDescriptor& d : result.descriptors) {
        if (d.metric == result.descriptors.front().metric) continue;
        std::string kinds;
        for (const RunDescriptor& e : result.descriptors)
          kinds += (kinds.empty() ? "" : ", ") + e.name + ": " + DistanceText(e.metric);
        std::string example = "1";
        for (size_t k = 1; k < names.size(); ++k) example += ",1";
        throw InputError("Fusion_weights: empty, but Image_descriptor \"" +
                         config.descriptor.name + "\" fuses distances of different kinds (" +
                         kinds + "); expected one weight per descriptor, e.g. Fusion_weights: " +
                         example);
      }
    }
  } else if (!matching.fusion_weights.empty()) {
    result.notes.push_back("Fusion_weights: \"" + matching.fusion_weights + "\" not used: "
                           "Image_descriptor " + names.front() + " is one descriptor");
  }

  const bool panoramic = input.camera_type == CameraType::kPanoramic;
  const int strips = panoramic ? config.description.panoramas : 1;
  const PanoramaMatching panorama_matching = matching.panorama_matching;
  // The row of a frame, refused up front when it cannot be held: Patch_size 1024 with a 64 x 32
  // grid of HOG cells would need gigabytes per frame (and overflow the row's int width).
  const int cells = (config.description.type == DescriptionType::kGrid
                         ? config.description.grid_x * config.description.grid_y
                         : 1) *
                    strips;
  std::int64_t row_bytes = 0;  // every descriptor's row of one frame
  for (size_t k = 0; k < descriptors.size(); ++k)
    row_bytes += static_cast<std::int64_t>(descriptors[k]->Width()) * cells *
                 (descriptors[k]->Kind() == DescriptorKind::kFloat ? 4 : 1);
  constexpr std::int64_t kMaxRowBytes = std::int64_t{1} << 30;
  if (row_bytes > kMaxRowBytes) {
    char text[96];
    std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(row_bytes) / kMaxRowBytes);
    throw InputError("Patch_size: " + std::to_string(config.descriptor.patch_size) + " with " +
                     (config.description.type == DescriptionType::kGrid
                          ? "Grid_x " + std::to_string(config.description.grid_x) + " x Grid_y " +
                                std::to_string(config.description.grid_y)
                          : std::string("the global description")) +
                     (strips > 1 ? " and " + std::to_string(strips) + " sub-panoramas" : "") +
                     " makes a descriptor row of " + text + " per frame (" +
                     config.descriptor.name + "); expected at most 1 GiB: a smaller Patch_size "
                     "or grid");
  }
  std::vector<std::unique_ptr<FrameDescriber>> describers;
  for (size_t k = 0; k < descriptors.size(); ++k) {
    describers.push_back(std::make_unique<FrameDescriber>(
        *descriptors[k], config.description.type, config.description.grid_x,
        config.description.grid_y, strips));
    result.descriptors[k].row_width = describers.back()->RowWidth();
  }
  const bool disparity = describers.front()->Channels() == 2;  // D-LDB, never fused
  // Eq. 7 replaces Alpha when the three peak responses are given.
  const bool lambdas = config.preprocess.lambda_red > 0;
  const double alpha = config.preprocess.Alpha();
  {
    char text[200];
    result.camera = panoramic ? "panoramic, " + std::to_string(strips) + " sub-panoramas, " +
                                    EnumName(panorama_matching) + " matching"
                  : input.camera_type == CameraType::kStereo
                      ? std::string("stereo, rectified") +
                            (disparity ? ", SGBM disparity" : ", left image")
                      : "monocular";
    if (config.preprocess.illumination_invariance) {
      std::snprintf(text, sizeof text, ", illumination invariant (Eq. 6, alpha %.4f%s)", alpha,
                    lambdas ? " from Eq. 7" : "");
      result.camera += text;
    } else {
      result.camera += ", grey";
    }
  }

  // Open every source first, so that a bad second folder is reported before any work.
  std::vector<std::unique_ptr<FrameSource>> sources;
  const std::vector<SourceSpec> specs = Sources(input);
  for (const auto& spec : specs) {
    if (spec.kind == SourceKind::kStereoBag) {
      StereoSourceOptions stereo_options;
      stereo_options.compute_disparity = disparity;
      const StereoCalibration calibration = WithKey(
          "Calibration_path", [&] { return LoadStereoCalibration(input.calibration_path); });
      SourceSpec right = spec;
      right.topic_key = "Bag_topic_right";
      right.topic = input.bag_topic_right;
      sources.push_back(OpenStereoSources(OpenStoredFrames(spec, input),
                                          OpenStoredFrames(right, input), calibration,
                                          stereo_options, "Bag_topic", "Bag_topic_right"));
      continue;
    }
    if (spec.kind == SourceKind::kStereo) {
      // The stereo source's messages name their keys (Images_path_left, Images_path_right,
      // Calibration_path) themselves.
      StereoSourceOptions stereo_options;
      stereo_options.compute_disparity = disparity;  // only D-LDB reads it
      const StereoCalibration calibration = WithKey(
          "Calibration_path", [&] { return LoadStereoCalibration(input.calibration_path); });
      sources.push_back(OpenStereoFolders(input.images_path_left, input.images_path_right,
                                          input.images_format, input.initial_image,
                                          input.final_image, calibration, stereo_options));
      continue;
    }
    sources.push_back(OpenStoredFrames(spec, input));  // folders, videos, bags
  }

  // The ratio score needs rivals: its window must leave references outside it.
  if (matching.score == MatchScore::kRatio) {
    const int references = sources.front()->Size();  // the reference traversal, or the one
    if (matching.score_window >= references)
      throw InputError("Match_score_window: " + std::to_string(matching.score_window) +
                       " is not smaller than the reference traversal (" +
                       std::to_string(references) + " frames of " + specs.front().key +
                       "); expected a window that leaves rivals outside it for Match_score "
                       "ratio (10 frames is typical), or Match_score distance");
  }

  // Verification reads the candidates' frames again: checked now, before the long part.
  if (config.verification.enabled) {
    // Frames of videos and bags have no file to read again.
    const SourceKind kind = specs.front().kind;
    const bool video = kind == SourceKind::kVideo || kind == SourceKind::kBag ||
                       kind == SourceKind::kStereoBag;
    const int query_frames = sources.back()->Size();
    const int queries = sources.size() > 1
                            ? query_frames
                            : std::max(0, query_frames - config.evaluation.protocol.exclusion);
    std::string first;
    cv::Size size;
    if (!video && !config.verification.calibration.empty()) {
      first = sources.front()->FrameName(0);
      size = WithKey(specs.front().key, [&] { return ReadImageFile(first).size(); });
    }
    CheckVerification(config, video, queries, first, size);
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
  if (static_cast<double>(row_bytes) * static_cast<double>(planned) > limit_bytes) {
    char text[160];
    std::snprintf(text, sizeof text, "%.2f GiB of descriptor rows (%lld frames of %.1f MB)",
                  static_cast<double>(row_bytes) * planned / gib, static_cast<long long>(planned),
                  row_bytes / 1e6);
    throw InputError(std::string("Patch_size: ") + std::to_string(config.descriptor.patch_size) +
                     " (" + config.descriptor.name + ") needs " + text + ", more than " +
                     (scale.memory_limit > 0 ? "Memory_limit" : "3/4 of the RAM") +
                     "; expected a smaller Patch_size or grid");
  }
  // Over processes, the dense matrix's ahead cells are filled once gathered, from the sums of
  // one direction; with both directions each direction's sums would be needed apart.
  if (!result.bounded && Cluster::Get().Distributed() && matching.sequence_length > 1 &&
      direction == SequenceDirection::kBoth && matching.partial == SequencePartial::kAhead)
    throw InputError("Sequence_partial: ahead with Sequence_direction 2 is not computed over "
                     "several processes (mpirun) in dense mode; expected Sequence_partial scale "
                     "or skip, Sequence_direction 0 or 1, or one process");
  if (result.bounded && stop == StopAfter::kSingleFrames)
    throw InputError("Auto: 1 compares dense matrices, but the run would be " +
                     result.mode_reason + "; expected a larger Memory_limit, or fewer frames "
                     "(the auto mode keeps one single-frame matrix per candidate descriptor)");
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
  // Fusion normalises each whole matrix and contrast enhancement reads a window of every row:
  // both need the dense matrix.
  if (result.bounded && fused)
    throw InputError("Image_descriptor: \"" + config.descriptor.name + "\" fuses descriptors, "
                     "which needs the dense matrix, but the run is " + result.mode_reason +
                     "; expected one descriptor, or Matrix_mode 1 (or 0 with a larger "
                     "Memory_limit)");
  if (result.bounded && matching.contrast_enhancement)
    throw InputError("Contrast_enhancement: 1 needs the dense matrix, but the run is " +
                     result.mode_reason + "; expected 0, or Matrix_mode 1 (or 0 with a larger "
                     "Memory_limit)");
  if (scale.approximate_search && result.descriptors.front().metric == Metric::kL1)
    throw InputError("Approximate_search: 1 with Image_descriptor " + names.front() +
                     " (L1 distance), which no approximate engine indexes; expected "
                     "Approximate_search 0 (the exact bounded mode) or another descriptor");
  if (stop == StopAfter::kChecks) return result;

  std::vector<int> starts;  // set from the first description
  auto set_traversals = [&](const std::vector<Traversal>& traversals) {
    if (result.traversals.empty()) {
      result.traversals = traversals;
      for (const auto& tr : traversals) starts.push_back(tr.first_row);
      return;
    }
    // Every descriptor reads the same frames; a frame readable for one and not another would
    // misalign the fused matrices.
    for (size_t s = 0; s < traversals.size(); ++s)
      if (traversals[s].names != result.traversals[s].names)
        throw InputError(traversals[s].key + ": the frames read differ between the fused "
                         "descriptors (a file changed during the run?); expected the same "
                         "frames for each");
  };

  if (result.bounded) {
    const Described described = DescribeSources(config, *describers.front(), names.front(),
                                                specs, sources, progress);
    set_traversals(described.traversals);
    result.cache = described.cache;
    AddLines(result.warnings, described.warnings);
    AddLines(result.notes, described.notes);
    result.timings.describe_seconds = described.seconds;
    result.timings.frames = described.frames;
    const std::int64_t n = described.rows.rows;
    const MatchBlock block = BlockOf(starts, static_cast<int>(n));
    KeepRules rules = scale.keep;
    rules.exclusion = config.evaluation.protocol.exclusion;
    rules.score = matching.score;
    rules.score_window = matching.score_window;
    rules.one_traversal = block.one_traversal;
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
    const auto t = Clock::now();
    result.timings.pairs =
        static_cast<std::int64_t>(block.query_count) * block.reference_count;
    Cluster& cluster = Cluster::Get();
    const auto [query_first, query_last] = cluster.Share(block.query_count);
    progress.Begin("matching", query_last - query_first,
                   "queries (bounded: ranges of rows" +
                       std::string(cluster.Distributed() ? ", this process's share)" : ")"));
    BoundedOptions options;
    options.metric = result.descriptors.front().metric;
    options.sequence_length = matching.sequence_length;
    options.direction = direction;
    options.partial = matching.partial;
    options.threads = matching.threads;
    // This process's share of the queries (all of them in a single process), raw or normalised
    // as `share` says.
    const auto match_share = [&](const BoundedOptions& share, float& largest) {
      if (scale.approximate_search)
        return ApproximateMatches(described.rows, block, rules, share, scale.approximate,
                                  largest);
      return BoundedMatches(described.rows, block, rules, share, largest,
                            [&](int done, int) { progress.Update(done); });
    };
    result.matches =
        SharedBoundedMatches(cluster, block, rules, options, match_share, result.max_distance);
    progress.End();
    cluster.Release();
    result.timings.match_seconds = SecondsSince(t);
    if (matching.match_threshold >= 0.0) CountAccepted(result, matching, result.matches);
    result.timings.total_seconds = SecondsSince(run_start);
    return result;
  }

  // Dense: every frame against every frame of the concatenated traversals, as the original;
  // one single-frame matrix per descriptor, from the store when a sweep computed it already.
  // Spread over processes, each computes the rows of its share (DenseShare) and process 0
  // gathers the normalised rows.
  Cluster& cluster = Cluster::Get();
  const bool cross = panoramic && panorama_matching != PanoramaMatching::kAligned;
  std::vector<const SingleFrame*> singles;
  std::vector<SingleFrame> computed;  // without a store
  computed.reserve(names.size());
  for (size_t k = 0; k < names.size(); ++k) {
    const std::string key = store ? SingleFrameKey(config, names[k]) : std::string();
    if (store)
      if (const SingleFrame* kept = store->Find(key)) {
        singles.push_back(kept);
        continue;
      }
    Config one = config;
    one.descriptor.name = names[k];
    Described described =
        DescribeSources(one, *describers[k], names[k], specs, sources, progress);
    SingleFrame frame;
    frame.descriptor = result.descriptors[k];
    frame.traversals = described.traversals;
    frame.cache = described.cache;
    frame.warnings = described.warnings;
    frame.notes = described.notes;
    frame.describe_seconds = described.seconds;
    frame.frames = described.frames;
    const std::int64_t n = described.rows.rows;
    frame.pairs = n * (n - 1) / 2;
    const auto t = Clock::now();
    // Spread over processes: this process's rows, with the L - 1 rows its sequences read.
    const DenseShare share =
        DenseShareOf(cluster, static_cast<int>(n), matching.sequence_length);
    const std::int64_t share_rows = share.last - share.history;
    progress.Begin("matching", share_rows * n * (cross ? strips * strips : 1),
                   std::string(cross ? "cells of sub-panorama pairs" : "cells") +
                       (fused ? " (" + names[k] + ")" : ""));
    const PairProgress on_pairs = [&](std::int64_t done, std::int64_t) {
      progress.Update(done);
    };
    cluster.Agree([&] {
      frame.distances = DistanceRows(described.rows, share.history, share.last,
                                     frame.descriptor.metric, strips, panorama_matching,
                                     matching.threads, on_pairs);
    });
    progress.End();
    frame.match_seconds = SecondsSince(t);
    if (store) {
      singles.push_back(&store->Keep(key, std::move(frame)));
    } else {
      computed.push_back(std::move(frame));
      singles.push_back(&computed.back());
    }
  }
  for (const SingleFrame* f : singles) {
    set_traversals(f->traversals);
    if (!f->cache.empty())
      result.cache += (result.cache.empty() ? "" : "; ") +
                      (fused ? f->descriptor.name + ": " : std::string()) + f->cache;
    AddLines(result.warnings, f->warnings);
    AddLines(result.notes, f->notes);
    result.timings.describe_seconds += f->describe_seconds;
    result.timings.match_seconds += f->match_seconds;
    result.timings.frames = f->frames;
    result.timings.pairs = f->pairs;
  }

  if (stop == StopAfter::kSingleFrames) return result;

  // Fusion (each matrix over its largest value, weighted), contrast enhancement, sequences,
  // Eq. 5, Eq. 9.
  const auto t = Clock::now();
  std::vector<const cv::Mat1f*> matrices;
  for (const SingleFrame* f : singles) matrices.push_back(&f->distances);
  // The store keeps its matrix for the next run; without one, the matrix is taken over.
  cv::Mat1f distances =
      FusedSingleFrame(matrices, result.fusion_weights, matching, starts, store != nullptr,
                       [&](double largest) { return cluster.Max(largest); });
  if (!store && !fused) computed.front().distances.release();
  if (!cluster.Distributed()) {
    SequenceDistancesInPlace(distances, matching.sequence_length, starts, starts, direction,
                             matching.threads, matching.partial);
    result.normalized = distances;
    distances.release();
    result.max_distance = NormalizeByMax(result.normalized);
  } else {
    // This process's rows: the sequences over its rows and the L - 1 before (a start of the
    // computed rows for the sums, which the kept rows never reach back to), Eq. 5 with the
    // largest value of every process, the rows gathered on process 0.
    const int n = distances.cols;
    const DenseShare share = DenseShareOf(cluster, n, matching.sequence_length);
    cv::Mat1f rows;
    float largest = 0.0f;
    // Sequence_partial ahead reads cells of later rows, which may belong to the next share:
    // each process leaves its early cells without a value (skip; they never set the largest
    // value, which ahead only copies) and process 0 fills them in the gathered matrix.
    const bool ahead = matching.partial == SequencePartial::kAhead;
    cluster.Agree([&] {
      SequenceDistancesInPlace(distances, matching.sequence_length,
                               ShareRowStarts(starts, share), starts, direction,
                               matching.threads,
                               ahead ? SequencePartial::kSkip : matching.partial);
      rows = distances.rowRange(share.first - share.history, share.last - share.history);
      largest = LargestFiniteEntry(rows);
    });
    result.max_distance = static_cast<float>(cluster.Max(largest));
    DivideByLargest(rows, result.max_distance);
    result.normalized = GatherRows(cluster, rows, n, n);
    distances.release();
    cluster.Release();
    if (cluster.Rank() != 0) return result;  // process 0 keeps the matrix and goes on
    if (ahead && matching.sequence_length > 1) {
      FillAheadCells(result.normalized, matching.sequence_length, starts, starts,
                     direction == SequenceDirection::kReverse);
    }
  }
  if (matching.partial != SequencePartial::kScale)
    result.empty_cells = static_cast<std::int64_t>(result.normalized.total()) -
                         cv::countNonZero(result.normalized <= 1.0f);
  if (matching.threshold >= 0.0)
    result.thresholded =
        ThresholdMatrix(result.normalized, static_cast<float>(matching.threshold));
  const MatchBlock block = BlockOf(starts, result.normalized.rows);
  KeepRules rules = scale.keep;
  rules.exclusion = config.evaluation.protocol.exclusion;
  rules.score = matching.score;
  rules.score_window = matching.score_window;
  rules.one_traversal = block.one_traversal;
  if (!scale.matches_name.empty())
    result.matches = MatchesFromMatrix(result.normalized, block, rules);
  if (matching.match_threshold >= 0.0) {
    KeepRules best = rules;
    best.best = 1;
    best.band = -1;
    CountAccepted(result, matching, MatchesFromMatrix(result.normalized, block, best));
  }
  result.timings.sequence_seconds = SecondsSince(t);
  result.timings.total_seconds = SecondsSince(run_start);
  return result;
}

}  // namespace

RunResult ComputeRun(const Config& config, ProgressReporter& progress, SingleFrameStore* store) {
  return ComputeOrCheckRun(config, progress, store, StopAfter::kRun);
}

void CheckRun(const Config& config) {
  ProgressReporter silent(std::cerr, false, false);
  ComputeOrCheckRun(config, silent, nullptr, StopAfter::kChecks);
}

RunResult ComputeSingleFrames(const Config& config, ProgressReporter& progress,
                              SingleFrameStore& store) {
  if (config.scale.matrix_mode == MatrixMode::kBounded || config.scale.approximate_search)
    throw std::logic_error("ComputeSingleFrames: a dense run expected");
  return ComputeOrCheckRun(config, progress, &store, StopAfter::kSingleFrames);
}

cv::Mat1f SingleFrameMatrix(const Config& config, const SingleFrameStore& store,
                            const std::vector<int>& starts) {
  const std::vector<std::string> names = DescriptorList(config.descriptor.name);
  std::vector<const cv::Mat1f*> matrices;
  for (const std::string& name : names) {
    const SingleFrame* kept = store.Find(SingleFrameKey(config, name));
    if (kept == nullptr)
      throw std::logic_error("SingleFrameMatrix: no single-frame matrix of " + name);
    matrices.push_back(&kept->distances);
  }
  const std::vector<double> weights =
      names.size() > 1 ? config.matching.FusionWeights(static_cast<int>(names.size()))
                       : std::vector<double>{1.0};
  return FusedSingleFrame(matrices, weights, config.matching, starts, true,
                          [](double largest) { return largest; });
}

EvaluationLayout LayoutOf(const RunResult& result) {
  if (result.traversals.size() == 2)
    return EvaluationLayout::TwoTraversals(result.traversals[0].frames,
                                           result.traversals[1].frames);
  if (result.traversals.size() != 1)
    throw std::logic_error("LayoutOf: a run has one or two traversals");
  return EvaluationLayout::LoopClosure(result.normalized.rows);
}

}  // namespace openable
