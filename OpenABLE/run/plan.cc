#include "OpenABLE/run/plan.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "OpenABLE/base/error.h"
#include "OpenABLE/cluster/cluster.h"
#include "OpenABLE/describe/describe.h"
#include "OpenABLE/run/given_rows.h"
#include "OpenABLE/run/verify.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/stereo_source.h"
#include "descriptors/registry.h"

namespace openable {

std::vector<SourceSpec> SourcesOf(const InputOptions& c) {
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

namespace {

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
    return OpenImageFolder(spec.path, input.images_format, input.initial_image, input.final_image);
  });
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * page : 8.0 * (1 << 30);
}

const char* DistanceText(Metric m) {
  switch (m) {
    case Metric::kHamming:
      return "Hamming";
    case Metric::kL2:
      return "L2";
    case Metric::kL1:
      break;
  }
  return "L1";
}

}  // namespace

std::vector<std::unique_ptr<FrameSource>> OpenFramesToShow(const InputOptions& input) {
  std::vector<std::unique_ptr<FrameSource>> sources;
  for (const SourceSpec& spec : SourcesOf(input)) sources.push_back(OpenStoredFrames(spec, input));
  return sources;
}

namespace {

// The frames of a source at `indices`, renumbered from 0: the rows a run kept.
class SelectedFrames final : public FrameSource {
 public:
  SelectedFrames(std::unique_ptr<FrameSource> source, std::vector<int> indices)
      : source_(std::move(source)), indices_(std::move(indices)) {}
  int Size() const override { return static_cast<int>(indices_.size()); }
  std::string FrameName(int i) const override { return source_->FrameName(indices_.at(i)); }
  cv::Mat Read(int i) const override { return source_->Read(indices_.at(i)); }
  bool ParallelReads() const override { return source_->ParallelReads(); }
  double Timestamp(int i) const override { return source_->Timestamp(indices_.at(i)); }

 private:
  std::unique_ptr<FrameSource> source_;
  std::vector<int> indices_;
};

}  // namespace

std::vector<std::unique_ptr<FrameSource>> FramesOfRows(
    std::vector<std::unique_ptr<FrameSource>> sources, const std::vector<Traversal>& traversals) {
  if (sources.size() != traversals.size())
    throw std::logic_error("FramesOfRows: " + std::to_string(sources.size()) + " sources for " +
                           std::to_string(traversals.size()) + " traversals");
  for (std::size_t t = 0; t < sources.size(); ++t) {
    const Traversal& tr = traversals[t];
    if (tr.skipped.empty() && sources[t]->Size() == tr.frames) continue;
    // The kept frames are in the source's order: one pass matches them by name.
    std::vector<int> indices;
    indices.reserve(tr.names.size());
    int next = 0;
    for (const std::string& name : tr.names) {
      while (next < sources[t]->Size() && sources[t]->FrameName(next) != name) ++next;
      if (next == sources[t]->Size())
        throw std::logic_error("FramesOfRows: frame " + Quoted(name) + " of " + tr.key +
                               " is not among its source's frames");
      indices.push_back(next++);
    }
    sources[t] = std::make_unique<SelectedFrames>(std::move(sources[t]), std::move(indices));
  }
  return sources;
}

namespace {

// The descriptor of rows given by Descriptors_path (and Descriptors_path_2), each file read and
// checked; what the run does not do with them refused, and Image_descriptor said unused.
std::unique_ptr<Descriptor> GivenRowsOf(const Config& config, RunResult& result) {
  const InputOptions& input = config.input;
  const std::vector<SourceSpec> specs = SourcesOf(input);
  if (config.description.type != DescriptionType::kGlobal ||
      input.camera_type != CameraType::kMonocular)
    throw InputError(
        "Descriptors_path: given with " +
        std::string(config.description.type != DescriptionType::kGlobal
                        ? "Description_type grid"
                        : "Camera_type " + std::to_string(static_cast<int>(input.camera_type))) +
        "; expected one row per frame of one camera (Description_type global, "
        "Camera_type 0)");
  if (specs.size() == 2 && input.descriptors_path_2.empty())
    throw InputError("Descriptors_path_2: empty, but the run has a second traversal (" +
                     specs[1].key + "); expected the rows of its frames too");
  if (specs.size() == 1 && !input.descriptors_path_2.empty())
    throw InputError("Descriptors_path_2: " + Quoted(input.descriptors_path_2) +
                     " given, but the run has one traversal; expected it with a second one");
  std::vector<cv::Mat> rows = {ReadGivenRows(input.descriptors_path, "Descriptors_path")};
  if (specs.size() == 2) {
    rows.push_back(ReadGivenRows(input.descriptors_path_2, "Descriptors_path_2"));
    const auto text = [](const cv::Mat& m) {
      return std::to_string(m.cols) + (m.type() == CV_32F ? " float32" : " uint8") + " values";
    };
    if (rows[1].cols != rows[0].cols || rows[1].type() != rows[0].type())
      throw InputError("Descriptors_path_2: rows of " + text(rows[1]) +
                       ", Descriptors_path rows of " + text(rows[0]) +
                       "; expected rows of one width and type for both traversals");
  }
  if (config.descriptor.name != DescriptorOptions().name && Upper(config.descriptor.name) != "NPY")
    result.notes.push_back("Image_descriptor: \"" + config.descriptor.name +
                           "\" not used: the rows come from Descriptors_path");
  return std::make_unique<GivenRowsDescriptor>(config.descriptor, std::move(rows));
}

// The descriptors of Image_descriptor, each created (and so checked), their fusion checked,
// the row of a frame refused when it cannot be held, and the camera described.
void PlanDescriptors(RunPlan& plan) {
  const Config& config = plan.config;
  const InputOptions& input = config.input;
  const MatchingOptions& matching = config.matching;
  RunResult& result = plan.head;
  const bool given = !input.descriptors_path.empty();
  plan.names = given ? std::vector<std::string>{"NPY"} : DescriptorList(config.descriptor.name);
  const std::vector<std::string>& names = plan.names;
  const bool fused = plan.Fused();
  if (given) plan.descriptors.push_back(GivenRowsOf(config, result));
  for (const std::string& name : names) {
    DescriptorOptions o = config.descriptor;
    o.name = name;
    if (!given) plan.descriptors.push_back(CreateDescriptor(o));
    if (fused && plan.descriptors.back()->Channels() == 2)
      throw InputError("Image_descriptor: \"" + config.descriptor.name + "\" fuses " + name +
                       ", whose stereo frames carry a disparity channel the others do not "
                       "read; expected " +
                       name + " alone");
    result.descriptors.push_back({name, 0, MetricOf(*plan.descriptors.back())});
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
        throw InputError("Fusion_weights: empty, but Image_descriptor \"" + config.descriptor.name +
                         "\" fuses distances of different kinds (" + kinds +
                         "); expected one weight per descriptor, e.g. Fusion_weights: " + example);
      }
    }
  } else if (!matching.fusion_weights.empty()) {
    result.notes.push_back("Fusion_weights: \"" + matching.fusion_weights +
                           "\" not used: "
                           "Image_descriptor " +
                           names.front() + " is one descriptor");
  }

  const bool panoramic = input.camera_type == CameraType::kPanoramic;
  plan.strips = panoramic ? config.description.panoramas : 1;
  const int strips = plan.strips;
  const PanoramaMatching panorama_matching = matching.panorama_matching;
  plan.cross = panoramic && panorama_matching != PanoramaMatching::kAligned;
  // The row of a frame, refused up front when it cannot be held: Patch_size 1024 with a 64 x 32
  // grid of HOG cells would need gigabytes per frame (and overflow the row's int width).
  const int cells = (config.description.type == DescriptionType::kGrid
                         ? config.description.grid_x * config.description.grid_y
                         : 1) *
                    strips;
  for (const auto& descriptor : plan.descriptors)
    plan.row_bytes += static_cast<std::int64_t>(descriptor->Width()) * cells *
                      (descriptor->Kind() == DescriptorKind::kFloat ? 4 : 1);
  constexpr std::int64_t kMaxRowBytes = std::int64_t{1} << 30;
  if (plan.row_bytes > kMaxRowBytes) {
    char text[96];
    std::snprintf(text, sizeof text, "%.1f GiB",
                  static_cast<double>(plan.row_bytes) / kMaxRowBytes);
    throw InputError("Patch_size: " + std::to_string(config.descriptor.patch_size) + " with " +
                     (config.description.type == DescriptionType::kGrid
                          ? "Grid_x " + std::to_string(config.description.grid_x) + " x Grid_y " +
                                std::to_string(config.description.grid_y)
                          : std::string("the global description")) +
                     (strips > 1 ? " and " + std::to_string(strips) + " sub-panoramas" : "") +
                     " makes a descriptor row of " + text + " per frame (" +
                     config.descriptor.name +
                     "); expected at most 1 GiB: a smaller Patch_size "
                     "or grid");
  }
  for (size_t k = 0; k < plan.descriptors.size(); ++k) {
    plan.describers.push_back(std::make_unique<FrameDescriber>(
        *plan.descriptors[k], config.description.type, config.description.grid_x,
        config.description.grid_y, strips));
    result.descriptors[k].row_width = plan.describers.back()->RowWidth();
  }
  const bool disparity = plan.describers.front()->Channels() == 2;  // D-LDB, never fused
  // Eq. 7 replaces Alpha when the three peak responses are given.
  const bool lambdas = config.preprocess.lambda_red > 0;
  const double alpha = config.preprocess.Alpha();
  char text[200];
  result.camera =
      panoramic ? "panoramic, " + std::to_string(strips) + " sub-panoramas, " +
                      EnumName(panorama_matching) + " matching"
      : input.camera_type == CameraType::kStereo
          ? std::string("stereo, rectified") + (disparity ? ", SGBM disparity" : ", left image")
          : "monocular";
  if (config.preprocess.illumination_invariance) {
    std::snprintf(text, sizeof text, ", illumination invariant (Eq. 6, alpha %.4f%s)", alpha,
                  lambdas ? " from Eq. 7" : "");
    result.camera += text;
  } else {
    result.camera += ", grey";
  }
}

// Opens every source first, so that a bad second folder is reported before any work.
void OpenSources(RunPlan& plan) {
  const InputOptions& input = plan.config.input;
  const bool disparity = plan.describers.front()->Channels() == 2;
  plan.specs = SourcesOf(input);
  for (const auto& spec : plan.specs) {
    if (spec.kind != SourceKind::kStereo && spec.kind != SourceKind::kStereoBag) {
      plan.sources.push_back(OpenStoredFrames(spec, input));  // folders, videos, bags
      continue;
    }
    // Stereo pairs, rectified with the calibration; the stereo source's messages name their
    // keys (Images_path_left, Images_path_right, Bag_topic_right, Calibration_path) themselves.
    StereoSourceOptions stereo_options;
    stereo_options.compute_disparity = disparity;  // only D-LDB reads it
    const StereoCalibration calibration =
        WithKey("Calibration_path", [&] { return LoadStereoCalibration(input.calibration_path); });
    if (spec.kind == SourceKind::kStereo) {
      plan.sources.push_back(OpenStereoFolders(input.images_path_left, input.images_path_right,
                                               input.images_format, input.initial_image,
                                               input.final_image, calibration, stereo_options));
      continue;
    }
    SourceSpec right = spec;
    right.topic_key = "Bag_topic_right";
    right.topic = input.bag_topic_right;
    plan.sources.push_back(OpenStereoSources(OpenStoredFrames(spec, input),
                                             OpenStoredFrames(right, input), calibration,
                                             stereo_options, "Bag_topic", "Bag_topic_right"));
  }
}

// The checks that read the opened sources: the ratio score's window against the reference
// frames, and the verification settings (its frames are read again later).
void CheckAgainstSources(const RunPlan& plan) {
  const Config& config = plan.config;
  const MatchingOptions& matching = config.matching;
  // Given rows: one per frame the run reads.
  for (size_t s = 0; s < plan.sources.size(); ++s)
    if (const cv::Mat* rows = plan.describers.front()->GivenRows(static_cast<int>(s)))
      if (rows->rows != plan.sources[s]->Size()) {
        const std::string key = s == 0 ? "Descriptors_path" : "Descriptors_path_2";
        throw InputError(
            key + " " +
            Quoted(s == 0 ? config.input.descriptors_path : config.input.descriptors_path_2) +
            ": " + std::to_string(rows->rows) + " rows, but " + plan.specs[s].key + " has " +
            std::to_string(plan.sources[s]->Size()) +
            " frames (Initial_image, Final_image applied); expected one row per "
            "frame, in the run's order");
      }
  // The ratio score needs rivals: its window must leave references outside it.
  // The reference traversal, or the one traversal.
  matching.score.CheckRivals(plan.sources.front()->Size(), plan.specs.front().key);
  if (!config.verification.enabled) return;
  // Frames of videos and bags have no file to read again.
  const SourceKind kind = plan.specs.front().kind;
  const bool video =
      kind == SourceKind::kVideo || kind == SourceKind::kBag || kind == SourceKind::kStereoBag;
  const int query_frames = plan.sources.back()->Size();
  const int queries = plan.sources.size() > 1
                          ? query_frames
                          : std::max(0, query_frames - config.evaluation.protocol.exclusion);
  std::string first;
  cv::Size size;
  if (!video && !config.verification.calibration.empty()) {
    // The size of the first frame, which the calibration must fit: the one frame the check
    // phase decodes.
    first = plan.sources.front()->FrameName(0);
    size = WithKey(plan.specs.front().key, [&] { return ReadImageFile(first).size(); });
  }
  CheckVerification(config, video, queries, first, size);
}

// Dense or bounded (Matrix_mode), said in one line, decided before any work from the frame
// counts of the sources (skipped frames can only make the matrix smaller), and the settings
// that need one mode or the other.
void DecideMode(RunPlan& plan, PlanScope scope) {
  const Config& config = plan.config;
  const MatchingOptions& matching = config.matching;
  RunResult& result = plan.head;
  std::int64_t planned = 0;
  for (const auto& source : plan.sources) planned += source->Size();
  const ScaleOptions& scale = config.scale;
  const SequenceDirection direction = matching.direction;
  const double gib = 1024.0 * 1024.0 * 1024.0;
  const double dense_bytes = static_cast<double>(planned) * planned * 4.0 *
                             (direction == SequenceDirection::kBoth ? 2.0 : 1.0);
  const double limit_bytes =
      scale.memory_limit > 0 ? scale.memory_limit * gib : 0.75 * PhysicalMemoryBytes();
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
    result.mode_reason =
        std::string(result.bounded ? "bounded" : "dense") + " (Matrix_mode 0: " + sizes + ")";
  }
  const double row_bytes = static_cast<double>(plan.row_bytes);
  if (row_bytes * static_cast<double>(planned) > limit_bytes) {
    char text[160];
    std::snprintf(text, sizeof text, "%.2f GiB of descriptor rows (%lld frames of %.1f MB)",
                  row_bytes * planned / gib, static_cast<long long>(planned), row_bytes / 1e6);
    throw InputError(std::string("Patch_size: ") + std::to_string(config.descriptor.patch_size) +
                     " (" + config.descriptor.name + ") needs " + text + ", more than " +
                     (scale.memory_limit > 0 ? "Memory_limit" : "3/4 of the RAM") +
                     "; expected a smaller Patch_size or grid");
  }
  // Over processes, the dense matrix's ahead cells are filled once gathered, from the sums of
  // one direction; with both directions each direction's sums would be needed apart.
  if (!result.bounded && Cluster::Get().Distributed() && matching.sequence_length > 1 &&
      direction == SequenceDirection::kBoth && matching.partial == SequencePartial::kAhead)
    throw InputError(
        "Sequence_partial: ahead with Sequence_direction 2 is not computed over "
        "several processes (mpirun) in dense mode; expected Sequence_partial scale "
        "or skip, Sequence_direction 0 or 1, or one process");
  if (result.bounded && scope == PlanScope::kSingleFrames)
    throw InputError("Auto: 1 compares dense matrices, but the run would be " + result.mode_reason +
                     "; expected a larger Memory_limit, or fewer frames "
                     "(the auto mode keeps one single-frame matrix per candidate descriptor)");
  if (result.bounded && scale.matches_name.empty())
    throw InputError("Matches_name: empty, but the run is " + result.mode_reason +
                     " and keeps only matches; expected a .npy or .csv path (or a larger "
                     "Memory_limit for the dense matrix)");
  const PanoramaMatching panorama_matching = matching.panorama_matching;
  if (result.bounded && config.input.camera_type == CameraType::kPanoramic &&
      panorama_matching != PanoramaMatching::kAligned)
    throw InputError(std::string("Panorama_matching: ") +
                     std::to_string(static_cast<int>(panorama_matching)) + " (" +
                     EnumName(panorama_matching) +
                     ") needs the dense "
                     "matrix, but the run is " +
                     result.mode_reason +
                     "; expected Matrix_mode 1 (or 0 with a larger Memory_limit) or "
                     "Panorama_matching 0");
  // Fusion normalises each whole matrix and contrast enhancement reads a window of every row:
  // both need the dense matrix.
  if (result.bounded && plan.Fused())
    throw InputError("Image_descriptor: \"" + config.descriptor.name +
                     "\" fuses descriptors, "
                     "which needs the dense matrix, but the run is " +
                     result.mode_reason +
                     "; expected one descriptor, or Matrix_mode 1 (or 0 with a larger "
                     "Memory_limit)");
  if (result.bounded && matching.contrast.enabled)
    throw InputError("Contrast_enhancement: 1 needs the dense matrix, but the run is " +
                     result.mode_reason +
                     "; expected 0, or Matrix_mode 1 (or 0 with a larger "
                     "Memory_limit)");
  if (scale.approximate_search && result.descriptors.front().metric == Metric::kL1)
    throw InputError("Approximate_search: 1 with Image_descriptor " + plan.names.front() +
                     " (L1 distance), which no approximate engine indexes; expected "
                     "Approximate_search 0 (the exact bounded mode) or another descriptor");
}

}  // namespace

RunPlan PlanRun(const Config& config, PlanScope scope) {
  CheckConfig(config);
  RunPlan plan;
  plan.config = config;
  PlanDescriptors(plan);
  OpenSources(plan);
  CheckAgainstSources(plan);
  DecideMode(plan, scope);
  return plan;
}

}  // namespace openable
