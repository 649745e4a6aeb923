#include "OpenABLE/online/online.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/core/utility.hpp>
#include <set>
#include <sstream>
#include <utility>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/online/map_file.h"
#include "descriptors/registry.h"
#include "matching/agreement.h"
#include "matching/contrast.h"
#include "matching/matrix.h"
#include "matching/search/incremental_index.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

void Require(bool ok, const std::string& field, const std::string& value,
             const std::string& expected) {
  if (!ok) throw InputError("OnlineOptions." + field + " = " + value + ": expected " + expected);
}

// A frame (`what`) of size `size` joining a map whose frames are `map_size` ("" = unknown).
void CheckFrameSize(const std::string& what, const std::string& size, const std::string& map_size) {
  if (!map_size.empty() && size != map_size)
    throw InputError(what + " is " + size + "; the map's frames are " + map_size +
                     " (expected frames of one camera at one size)");
}

// The names of `descriptor` (a fusion "HOG+LDB" or one name), then those of `kept` not among
// them, upper case as the registry names them.
std::vector<std::string> ChannelNames(const std::string& descriptor, const std::string& kept) {
  std::vector<std::string> names;
  for (const std::string& text : {descriptor, kept}) {
    if (text.empty() && &text != &descriptor) continue;
    for (const std::string& name : DescriptorList(text)) {
      const std::string upper = Upper(name);
      if (std::find(names.begin(), names.end(), upper) == names.end()) names.push_back(upper);
    }
  }
  return names;
}

// The largest finite value of `m` (0 when none).
double LargestFinite(const cv::Mat1f& m) {
  double largest = 0;
  for (int i = 0; i < m.rows; ++i) {
    const float* p = m.ptr<float>(i);
    for (int j = 0; j < m.cols; ++j)
      if (std::isfinite(p[j]) && p[j] > largest) largest = p[j];
  }
  return largest;
}

}  // namespace

void OnlineOptions::Check() const {
  Require(description == DescriptionType::kGlobal || description == DescriptionType::kGrid,
          "description", std::to_string(static_cast<int>(description)), "global or grid");
  Require(grid_x >= 1 && grid_x <= 64, "grid_x", std::to_string(grid_x), "1..64");
  Require(grid_y >= 1 && grid_y <= 64, "grid_y", std::to_string(grid_y), "1..64");
  Require(sequence_length >= 1 && sequence_length <= 1000, "sequence_length",
          std::to_string(sequence_length), "1..1000");
  Require(contrast.window >= 1 && contrast.window <= 100000, "contrast_window",
          std::to_string(contrast.window), "1..100000");
  Require(exclusion >= 1, "exclusion", std::to_string(exclusion),
          ">= 1 (frames between a frame and its earliest candidate)");
  Require(candidates >= 1 && candidates <= 1000, "candidates", std::to_string(candidates),
          "1..1000");
  Require(std::isfinite(threshold), "threshold", std::to_string(threshold),
          "a number >= 0, or < 0 for the score's default");
  Require(score.kind == MatchScore::kDistance || score.kind == MatchScore::kRatio, "score",
          std::to_string(static_cast<int>(score.kind)), "distance or ratio");
  Require(score.window >= 0, "score_window", std::to_string(score.window),
          ">= 0 (frames on each side of a candidate that are not its rivals)");
  Require(consistency >= 0 && consistency <= 1000, "consistency", std::to_string(consistency),
          "0..1000 (earlier independent queries that must agree; 0: off)");
  Require(exact_limit >= 0, "exact_limit", std::to_string(exact_limit), ">= 0");
  Require(block_frames >= 16, "block_frames", std::to_string(block_frames), ">= 16");
  const std::vector<std::string> names = DescriptorList(descriptor.name);
  if (!kept_descriptors.empty()) {
    try {
      DescriptorList(kept_descriptors);
    } catch (const InputError& e) {
      throw InputError("OnlineOptions.kept_descriptors = " + Quoted(kept_descriptors) + ": " +
                       e.what());
    }
  }
  if (!fusion_weights.empty()) {
    Require(fusion_weights.size() == names.size(), "fusion_weights",
            std::to_string(fusion_weights.size()) + " weights",
            "one per descriptor of " + Quoted(descriptor.name) + " (" +
                std::to_string(names.size()) + "), or none for equal weights");
    for (const double w : fusion_weights)
      Require(std::isfinite(w) && w > 0, "fusion_weights", FormatNumber(w), "weights > 0");
  }
  try {
    approximate.Check();
  } catch (const std::exception& e) {
    throw InputError("OnlineOptions.approximate: " + std::string(e.what()));
  }
  CheckEngineAvailable(approximate.engine, "OnlineOptions.approximate.engine");
  Require(approximate.k >= candidates, "approximate.k", std::to_string(approximate.k),
          ">= candidates (" + std::to_string(candidates) + ")");
  if (verification.enabled) {
    try {
      verification.Check();
    } catch (const std::exception& e) {
      throw InputError("OnlineOptions.verification: " + std::string(e.what()));
    }
    Require(approximate.k >= verification.candidates, "approximate.k",
            std::to_string(approximate.k),
            ">= verification.candidates (" + std::to_string(verification.candidates) + ")");
  }
}

std::string AbsoluteModelPath(const std::string& path) {
  if (path.empty()) return path;
  std::error_code error;
  const std::filesystem::path absolute = std::filesystem::absolute(path, error);
  return error ? path : absolute.lexically_normal().string();
}

Describer MakeDescriber(const OnlineOptions& options) {
  options.Check();
  Describer out;
  out.descriptor = CreateDescriptor(options.descriptor);
  // A grey image per frame (a colour one for a network): D-LDB's grey + disparity needs
  // stereo pairs.
  Require(out.descriptor->Channels() != 2, "descriptor", options.descriptor.name,
          "a single-camera descriptor (" + out.descriptor->Name() +
              " needs stereo pairs: use Test_OpenABLE with Camera_type 1)");
  // DenseVLAD's rows depend on the vocabulary learnt from a reference traversal: frames
  // described one call at a time (or a map's later sessions) would each learn another.
  if (out.descriptor->Learns())
    throw InputError("descriptor: " + out.descriptor->Name() +
                     " learns its vocabulary from a "
                     "reference traversal, which the online detector, maps and describe() do "
                     "not keep; expected a run of the whole traversals (Test_OpenABLE, "
                     "openable.sweep or python3 -m openable run), or another descriptor here");
  out.frame = std::make_unique<FrameDescriber>(*out.descriptor, options.description, options.grid_x,
                                               options.grid_y, 1);
  return out;
}

namespace {

// The images of one frame a describer takes: grey (GreyOfImage), and colour for a network
// (ColourOfImage), each made once when a describer needs it.
struct FrameImages {
  const cv::Mat& image;
  const std::string& what;
  cv::Mat grey, colour;
  const cv::Mat& For(const FrameDescriber& describer) {
    if (describer.Channels() == 3) {
      if (colour.empty()) colour = ColourOfImage(image, what);
      return colour;
    }
    return Grey();
  }
  const cv::Mat& Grey() {
    if (grey.empty()) grey = GreyOfImage(image, what);
    return grey;
  }
};

// Describes the image of a frame `describer` takes with it, checking its size.
void DescribeInto(const FrameDescriber& describer, FrameImages& images, cv::Mat row) {
  const cv::Mat& image = images.For(describer);
  const cv::Size need = describer.MinimumFrame();
  if (image.cols < need.width || image.rows < need.height)
    throw InputError(images.what + " is " + SizeText(image.size()) + "; the grid needs at least " +
                     SizeText(need) + " pixels (grid_x by grid_y)");
  describer.Describe(image, row);
}

// The name of image i in messages: `names[i]` quoted as a file, or "image i".
std::string ImageName(const std::vector<std::string>& names, int i) {
  return names.empty() ? "image " + std::to_string(i)
                       : "frame " + Quoted(names[static_cast<size_t>(i)]);
}

// One row per image and describer, described in parallel; the first image that cannot be
// described gives the error.
std::vector<cv::Mat> DescribeNamed(const std::vector<const FrameDescriber*>& describers,
                                   const std::vector<cv::Mat>& images,
                                   const std::vector<std::string>& names, int threads) {
  const int n = static_cast<int>(images.size());
  std::vector<cv::Mat> rows;
  for (const FrameDescriber* d : describers) rows.emplace_back(n, d->RowWidth(), d->RowType());
  if (n == 0) return rows;
  std::mutex mutex;
  int error_index = n;
  std::string error;
  ParallelFor(n, threads, [&](int i) {
    try {
      const std::string what = ImageName(names, i);
      FrameImages frame{images[i], what, {}, {}};
      for (size_t c = 0; c < describers.size(); ++c)
        DescribeInto(*describers[c], frame, rows[c].row(i));
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      if (i < error_index) error_index = i, error = e.what();
    }
  });
  if (error_index < n) throw InputError(error);
  return rows;
}

}  // namespace

cv::Mat DescribeImages(const std::vector<cv::Mat>& images, const OnlineOptions& options,
                       int threads) {
  const Describer d = MakeDescriber(options);
  return DescribeNamed({d.frame.get()}, images, {}, threads).front();
}

cv::Mat1f DistanceMatrix(const cv::Mat& rows, int sequence_length, SequenceDirection direction,
                         const std::vector<int>& traversal_starts, int threads, float* max_distance,
                         std::optional<Metric> metric, SequencePartial partial) {
  if (rows.empty() || (rows.type() != CV_8UC1 && rows.type() != CV_32FC1))
    throw InputError("descriptor rows of OpenCV type " + cv::typeToString(rows.type()) + " and " +
                     std::to_string(rows.rows) +
                     " rows: expected at least one row of CV_8UC1 "
                     "(Hamming) or CV_32FC1 (L2)");
  if (sequence_length < 1)
    throw InputError("sequence_length = " + std::to_string(sequence_length) + ": expected >= 1");
  const Metric m = metric.value_or(MetricOfType(rows.type()));
  if ((m == Metric::kL2) != (rows.type() == CV_32FC1))
    throw InputError("descriptor rows of OpenCV type " + cv::typeToString(rows.type()) +
                     " with the " + EnumName(m) +
                     " distance: expected CV_32FC1 rows for l2, "
                     "CV_8UC1 rows for hamming and l1");
  return NormalizedDistanceMatrix(rows, sequence_length, direction, traversal_starts, threads,
                                  max_distance, m, partial);
}

// ---- OnlineDetector ------------------------------------------------------------------------

namespace {

// The rows of the frames of one query traversal, one matrix per channel of the map (row i:
// frame i).
using RowsByChannel = std::vector<cv::Mat>;

// The map frames a search scores: ranges [first, first + count) of whole or partial sessions,
// in frame order, laid side by side as the columns of its single-frame rows.
struct Columns {
  std::vector<std::pair<int, int>> ranges;  // (first frame, count)
  std::vector<int> starts;                  // the column where each session starts
  int count = 0;
  // The map frame of column c.
  int Frame(int c) const {
    for (const auto& [first, n] : ranges) {
      if (c < n) return first + c;
      c -= n;
    }
    return -1;
  }
};

}  // namespace

struct OnlineDetector::State {
  // One descriptor of a map: its describer, how its rows compare, and the rows of every frame
  // (indexed beyond exact_limit for the map's index channel; a plain growing store otherwise).
  struct Channel {
    std::string name;
    Describer describer;
    Metric metric = Metric::kHamming;
    int width = 0, type = CV_8U;
    std::unique_ptr<IncrementalIndex> rows;
  };

  OnlineOptions options;
  std::vector<Channel> channels;  // the map's descriptors (Channels())
  int indexed = -1;               // the channel whose index finds candidates; -1: none
  std::vector<int> search;        // the channels of options.descriptor, in its order
  std::vector<double> weights;    // their fusion weights
  // Fusion: each search channel's distances are divided by its unit (the largest
  // single-frame distance of a matrix, as a run divides, Tune's; or of the map's first frames
  // when first needed). Empty until known; unused for one channel.
  std::vector<double> units;
  // Contrast enhancement: the shift added to every enhanced distance (Tune's, the run's
  // -smallest; else sqrt(2 window), below which no z-score of a window falls).
  double shift = -1;
  // `normalized` = distance / (L x unit): binary: bits per row; else the largest single-frame
  // distance computed so far; fused: the sum of the weights.
  double unit = 0;
  int packed_width = 0;  // bytes of a frame's rows side by side (several channels)
  MapTuning tuning;
  bool uses_tuning = false;
  // Verification: the checker, every frame's features, the previous frame's candidates.
  std::unique_ptr<PairVerifier> verifier;
  std::vector<FrameFeatures> features;
  QueryVerification previous;
  // Sessions, tiling frames 0 .. Size() - 1; the frames' size ("WxH", "" unknown).
  std::vector<MapSession> sessions;
  std::string frame_size;
  // The image file of each frame (AddImagesToMap's names, "" for others); empty: none known.
  std::vector<std::string> files;
  // A loaded map: its path and the background check of its checksums (map_file.h).
  std::string map_path;
  std::shared_future<std::string> map_check;
  // AddFrame while exact: the running sequence sums of the current traversal (its last row
  // is frame running_last, over running_columns columns), and the best candidate of each of
  // its frames (consistency).
  SequenceRowSums running{1};
  int running_last = -1, running_columns = 0;
  std::vector<int> answers;

  int Size() const { return channels.front().rows->Size(); }
  bool Several() const { return channels.size() > 1; }
  bool Fused() const { return search.size() > 1; }
  // Whether `unit` is fixed (bits of a binary row; the fusion's weights) rather than the
  // largest distance seen so far.
  bool UnitFixed() const {
    return Fused() || channels[static_cast<size_t>(search.front())].metric == Metric::kHamming;
  }
  std::vector<std::string> ChannelList() const {
    std::vector<std::string> out;
    for (const Channel& c : channels) out.push_back(c.name);
    return out;
  }
  IncrementalIndex* Index() const {
    return indexed >= 0 ? channels[static_cast<size_t>(indexed)].rows.get() : nullptr;
  }
  // Whether the search scans every frame (no index blocks in use, or contrast enhancement).
  bool Exact() const {
    const IncrementalIndex* index = Index();
    return options.contrast.enabled || index == nullptr || index->Blocks() == 0;
  }
  int SessionOf(int frame) const {
    auto it = std::upper_bound(sessions.begin(), sessions.end(), frame,
                               [](int f, const MapSession& m) { return f < m.first; });
    return static_cast<int>(it - sessions.begin()) - 1;
  }
  // `n` frames appended: they join the last session (one named "default" when none).
  void Appended(int n) {
    if (sessions.empty()) sessions.push_back({"default", MapTimeNow(), 0, 0});
    sessions.back().count += n;
  }

  void Build(const OnlineOptions& o, const std::vector<std::string>& names, int index_channel);
  void SetSearch();
  // Rows given by the caller (packed for several channels) as one matrix per channel.
  // `rows_text`: the rows expected, as messages name them ("n", or "1" for one row).
  RowsByChannel Split(const cv::Mat& rows, const std::string& what,
                      const std::string& rows_text = "n") const;
  cv::Mat Pack(const RowsByChannel& rows) const;
  void Append(const RowsByChannel& rows);
  // The fusion's units from the map's first frames when not known yet (several channels).
  void EnsureUnits();
  std::vector<double> UnitsNow() const;
  // The fused single-frame distances of query rows [a, b) of `queries` against `columns`,
  // contrast-enhanced as the options say: (b - a) x columns.count.
  cv::Mat1f SingleFrameRows(const RowsByChannel& queries, int a, int b, const Columns& columns,
                            const std::vector<double>& units) const;
  // The fused single-frame distance of query row q and map frame j.
  double PairDistance(const RowsByChannel& queries, int q, int j,
                      const std::vector<double>& units) const;
  // S(q, j) straight from the rows (the approximate path), the query's traversal starting at
  // its row q_first, the map frame's at its session's first frame; neither sequence runs
  // across its start. `largest` is raised to the largest single-frame distance summed.
  double CellDistance(const RowsByChannel& queries, int q, int q_first, int j,
                      const std::vector<double>& units, double* largest) const;
  // The search of the frame just appended (AddDescriptor, AddFrame).
  OnlineResult Search(const RowsByChannel& row);
  // The candidates kept of `scored` (distance, frame) and their scores, into r.candidates.
  void Choose(std::vector<std::pair<double, int>>& scored, double unit_now, OnlineResult& r) const;
  // The consistency of query `qi` of a traversal whose best candidates so far are `answers`
  // (answers[qi] set here from r), and the acceptance.
  void Confirm(OnlineResult& r, int qi, std::vector<int>& answers) const;
  AgreementOptions Agreement() const {
    AgreementOptions a;
    a.sequence_length = options.sequence_length;
    a.partial = SequencePartial::kScale;
    a.direction = SequenceDirection::kForward;
    a.partners = std::max(1, options.consistency);
    return a;
  }
  bool Unreliable() const { return uses_tuning && tuning.tuned && !tuning.reliable; }
  // A damaged loaded map (its background check failed): InputError. `wait`: wait for the
  // check; else only a check already finished counts.
  void ThrowIfDamaged(bool wait) const {
    if (!map_check.valid()) return;
    if (!wait && map_check.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    const std::string& error = map_check.get();
    if (!error.empty()) throw InputError(error);
  }
};

void OnlineDetector::State::Build(const OnlineOptions& o, const std::vector<std::string>& names,
                                  int index_channel) {
  channels.clear();
  packed_width = 0;
  for (const std::string& name : names) {
    Channel c;
    c.name = name;
    OnlineOptions one = o;
    one.descriptor.name = name;
    one.fusion_weights.clear();
    c.describer = MakeDescriber(one);
    c.metric = MetricOf(*c.describer.descriptor);
    c.width = c.describer.frame->RowWidth();
    c.type = c.describer.frame->RowType();
    packed_width += c.width * static_cast<int>(CV_ELEM_SIZE(c.type));
    channels.push_back(std::move(c));
  }
  // The index: on the channel named, else the first of the search's channels that has one,
  // else the first kept one that has one (L1 rows have none).
  indexed = index_channel;
  if (indexed < 0) {
    const std::vector<std::string> first = ChannelNames(o.descriptor.name, "");
    for (const std::string& want : first)
      for (size_t c = 0; c < channels.size() && indexed < 0; ++c)
        if (channels[c].name == want && channels[c].metric != Metric::kL1)
          indexed = static_cast<int>(c);
    for (size_t c = 0; c < channels.size() && indexed < 0; ++c)
      if (channels[c].metric != Metric::kL1) indexed = static_cast<int>(c);
  }
  for (size_t c = 0; c < channels.size(); ++c) {
    IncrementalIndexOptions index;
    index.exact_limit = static_cast<int>(c) == indexed ? o.exact_limit : INT_MAX;
    index.block_frames = o.block_frames;
    index.background_merges = o.background_merges;
    index.approximate = o.approximate;
    channels[c].rows =
        std::make_unique<IncrementalIndex>(channels[c].width, channels[c].type, index);
  }
  if (!Several() && channels.front().type == CV_8U && channels.front().metric == Metric::kHamming)
    unit = 8.0 * channels.front().width;
}

void OnlineDetector::State::SetSearch() {
  search.clear();
  for (const std::string& name : ChannelNames(options.descriptor.name, "")) {
    size_t c = 0;
    while (c < channels.size() && channels[c].name != name) ++c;
    if (c == channels.size())
      throw InputError("OnlineOptions.descriptor = " + Quoted(options.descriptor.name) +
                       ": the map holds rows of " + JoinStrings(ChannelList(), ", ") + " only; " +
                       "expected descriptors among them");
    search.push_back(static_cast<int>(c));
  }
  weights = options.fusion_weights.empty() ? std::vector<double>(search.size(), 1.0)
                                           : options.fusion_weights;
  if (Fused()) {
    unit = 0;
    for (const double w : weights) unit += w;
  } else if (channels[static_cast<size_t>(search.front())].metric == Metric::kHamming) {
    unit = 8.0 * channels[static_cast<size_t>(search.front())].width;
  }
  if (options.contrast.enabled && shift < 0) shift = std::sqrt(2.0 * options.contrast.window);
  // Another search than the one the units or shift were chosen for needs its own.
  if (units.size() != search.size()) units.clear();
  // The running sums and the answers of the current traversal were of the search before.
  running = SequenceRowSums(options.sequence_length, SequencePartial::kScale);
  running_last = -1;
  answers.clear();
}

RowsByChannel OnlineDetector::State::Split(const cv::Mat& rows, const std::string& what,
                                           const std::string& rows_text) const {
  const bool rows_ok = rows_text != "1" || rows.rows == 1;
  if (!Several()) {
    const State::Channel& c = channels.front();
    if (!rows_ok || rows.cols != c.width || rows.type() != c.type)
      throw InputError(what + " of " + std::to_string(rows.rows) + "x" + std::to_string(rows.cols) +
                       " " + cv::typeToString(rows.type()) + ": expected " + rows_text + "x" +
                       std::to_string(c.width) + " " + cv::typeToString(c.type) + " (" +
                       c.describer.descriptor->Name() + ")");
    if (c.type == CV_32F && !rows.empty() && !cv::checkRange(rows))
      throw InputError(what + " hold a value that is not finite");
    return {rows.isContinuous() ? rows : rows.clone()};
  }
  if (!rows_ok || rows.cols != packed_width || rows.type() != CV_8UC1)
    throw InputError(what + " of " + std::to_string(rows.rows) + "x" + std::to_string(rows.cols) +
                     " " + cv::typeToString(rows.type()) + ": expected " + rows_text + "x" +
                     std::to_string(packed_width) + " CV_8UC1 (the rows of " +
                     JoinStrings(ChannelList(), ", ") + " side by side)");
  RowsByChannel out;
  int offset = 0;
  for (const Channel& c : channels) {
    const int bytes = c.width * static_cast<int>(CV_ELEM_SIZE(c.type));
    cv::Mat m(rows.rows, c.width, c.type);
    for (int i = 0; i < rows.rows; ++i)
      std::memcpy(m.ptr(i), rows.ptr(i) + offset, static_cast<size_t>(bytes));
    if (c.type == CV_32F && !m.empty() && !cv::checkRange(m))
      throw InputError(what + " hold a " + c.name + " value that is not finite");
    out.push_back(std::move(m));
    offset += bytes;
  }
  return out;
}

cv::Mat OnlineDetector::State::Pack(const RowsByChannel& rows) const {
  if (!Several()) return rows.front();
  const int n = rows.front().rows;
  cv::Mat out(n, packed_width, CV_8UC1);
  int offset = 0;
  for (size_t c = 0; c < channels.size(); ++c) {
    const size_t bytes = static_cast<size_t>(rows[c].cols) * rows[c].elemSize();
    for (int i = 0; i < n; ++i) std::memcpy(out.ptr(i) + offset, rows[c].ptr(i), bytes);
    offset += static_cast<int>(bytes);
  }
  return out;
}

void OnlineDetector::State::Append(const RowsByChannel& rows) {
  const int n = rows.front().rows;
  if (!files.empty()) files.resize(files.size() + static_cast<size_t>(n));
  for (size_t c = 0; c < channels.size(); ++c) {
    IncrementalIndex& index = *channels[c].rows;
    if (n > 1) index.Reserve(index.Size() + n);
    for (int i = 0; i < n; ++i) index.Append(rows[c].row(i));
  }
}

std::vector<double> OnlineDetector::State::UnitsNow() const {
  if (!Fused() || !units.empty()) return units;
  // The largest single-frame distance among the map's first frames, per channel: fixed once
  // taken, so that every query of the map is scaled alike.
  const int n = std::min(Size(), 1000);
  std::vector<double> out;
  for (const int c : search) {
    const cv::Mat rows = channels[static_cast<size_t>(c)].rows->Rows().rowRange(0, n);
    out.push_back(
        n > 1 ? LargestFinite(Distances(rows, rows, channels[static_cast<size_t>(c)].metric))
              : 0.0);
  }
  return out;
}

void OnlineDetector::State::EnsureUnits() {
  if (Fused() && units.empty() && Size() > 1) units = UnitsNow();
}

double OnlineDetector::State::PairDistance(const RowsByChannel& queries, int q, int j,
                                           const std::vector<double>& u) const {
  if (!Fused()) {
    const State::Channel& c = channels[static_cast<size_t>(search.front())];
    return RowDistance(queries[static_cast<size_t>(search.front())], q, c.rows->Rows(), j,
                       c.metric);
  }
  double sum = 0;
  for (size_t k = 0; k < search.size(); ++k) {
    const State::Channel& c = channels[static_cast<size_t>(search[k])];
    if (u[k] <= 0) continue;  // a descriptor whose frames are all alike adds nothing
    sum += weights[k] / u[k] *
           RowDistance(queries[static_cast<size_t>(search[k])], q, c.rows->Rows(), j, c.metric);
  }
  return sum;
}

double OnlineDetector::State::CellDistance(const RowsByChannel& queries, int q, int q_first, int j,
                                           const std::vector<double>& u, double* largest) const {
  const MapSession& sj = sessions[static_cast<size_t>(SessionOf(j))];
  const int L = options.sequence_length;
  const int terms = SequenceTerms(L, std::min(q - q_first, j - sj.first));
  double sum = 0;
  for (int k = 0; k < terms; ++k) {
    const double d = PairDistance(queries, q - k, j - k, u);
    if (largest != nullptr && d > *largest) *largest = d;
    sum += d;
  }
  return ScaleSequenceSum(sum, terms, L, SequencePartial::kScale);
}

cv::Mat1f OnlineDetector::State::SingleFrameRows(const RowsByChannel& queries, int a, int b,
                                                 const Columns& columns,
                                                 const std::vector<double>& u) const {
  cv::Mat1f out = cv::Mat1f::zeros(b - a, columns.count);
  for (size_t k = 0; k < search.size(); ++k) {
    const State::Channel& c = channels[static_cast<size_t>(search[k])];
    const cv::Mat q = queries[static_cast<size_t>(search[k])].rowRange(a, b);
    const double factor = Fused() ? (u[k] > 0 ? weights[k] / u[k] : 0.0) : 1.0;
    if (factor == 0.0) continue;
    int col = 0;
    for (const auto& [first, n] : columns.ranges) {
      const cv::Mat1f d = Distances(q, c.rows->Rows().rowRange(first, first + n), c.metric);
      cv::Mat1f target = out.colRange(col, col + n);
      if (!Fused())
        d.copyTo(target);
      else
        cv::scaleAdd(d, factor, target, target);
      col += n;
    }
  }
  if (options.contrast.enabled) {
    EnhanceContrastUnshifted(out, options.contrast.window, columns.starts);
    // The tuned shift leaves a few of the new distances below 0: they are the best matches of
    // their row's window, kept at 0.
    out += static_cast<float>(shift);
    cv::max(out, 0.0f, out);
  }
  return out;
}

OnlineDetector::OnlineDetector(const OnlineOptions& options) : state_(std::make_unique<State>()) {
  State& s = *state_;
  options.Check();
  s.options = options;
  s.Build(options, ChannelNames(options.descriptor.name, options.kept_descriptors), -1);
  s.SetSearch();
  if (options.verification.enabled) {
    Require(!s.Several(), "verification.enabled", "true",
            "a map of one descriptor (verification keeps one row and its features a frame)");
    std::optional<CameraIntrinsics> camera;
    if (!options.verification.calibration.empty())
      camera = ReadVerificationCalibration(options.verification.calibration,
                                           options.verification.calibration_scale,
                                           "OnlineOptions.verification.calibration");
    s.verifier = std::make_unique<PairVerifier>(options.verification, camera);
  }
}

OnlineDetector::~OnlineDetector() = default;

const OnlineOptions& OnlineDetector::Options() const { return state_->options; }
int OnlineDetector::Size() const { return state_->Size(); }
int OnlineDetector::RowWidth() const {
  return state_->Several() ? state_->packed_width : state_->channels.front().width;
}
int OnlineDetector::RowType() const {
  return state_->Several() ? CV_8U : state_->channels.front().type;
}
cv::Mat OnlineDetector::Descriptors() const {
  const State& s = *state_;
  if (!s.Several()) return s.channels.front().rows->Rows();
  RowsByChannel rows;
  for (const State::Channel& c : s.channels) rows.push_back(c.rows->Rows());
  return s.Pack(rows);
}
std::vector<std::string> OnlineDetector::Channels() const {
  std::vector<std::string> out;
  for (const State::Channel& c : state_->channels) out.push_back(c.name);
  return out;
}
int OnlineDetector::Blocks() const {
  const IncrementalIndex* index = state_->Index();
  return index == nullptr ? 0 : index->Blocks();
}
void OnlineDetector::FinishMerges() {
  if (IncrementalIndex* index = state_->Index()) index->FinishMerges();
}
std::int64_t OnlineDetector::MemoryBytes() const {
  std::int64_t bytes = 0;
  for (const State::Channel& c : state_->channels) bytes += c.rows->MemoryBytes();
  return bytes;
}
const MapTuning& OnlineDetector::Tuning() const { return state_->tuning; }
bool OnlineDetector::UsesTuning() const { return state_->uses_tuning; }

OnlineResult OnlineDetector::AddFrame(const cv::Mat& image) {
  State& s = *state_;
  s.ThrowIfDamaged(false);
  const auto start = Clock::now();
  const std::string what = "frame " + std::to_string(Size());
  FrameImages frame{image, what, {}, {}};
  // The image the first descriptor takes (made once; the others reuse it) gives the size.
  const std::string size = SizeText(frame.For(*s.channels.front().describer.frame).size());
  CheckFrameSize(what, size, s.frame_size);
  RowsByChannel rows;
  for (const State::Channel& c : s.channels) {
    rows.emplace_back(1, c.width, c.type);
    DescribeInto(*c.describer.frame, frame, rows.back());
  }
  s.frame_size = size;
  const double describe = Seconds(start);
  if (!s.verifier) {
    OnlineResult r = s.Search(rows);
    r.describe_seconds = describe;
    return r;
  }
  const auto verify_start = Clock::now();
  s.features.push_back(s.verifier->Extract(frame.Grey()));
  double verify = Seconds(verify_start);
  OnlineResult r = s.Search(rows);
  r.describe_seconds = describe;
  // The candidates checked against this frame, then the temporal consistency.
  const auto check_start = Clock::now();
  QueryVerification current;
  current.query = r.frame;
  for (const LoopCandidate& c : r.candidates) {
    VerifiedCandidate v;
    v.reference = c.frame;
    v.check = s.verifier->Verify(s.features[r.frame], s.features[c.frame]);
    current.candidates.push_back(v);
  }
  ContinueStreaks(s.previous.candidates.empty() ? nullptr : &s.previous, current,
                  s.options.verification.consistency, s.options.verification.tolerance);
  for (std::size_t i = 0; i < r.candidates.size(); ++i) {
    LoopCandidate& c = r.candidates[i];
    const VerifiedCandidate& v = current.candidates[i];
    c.matches = v.check.matches;
    c.inliers = v.check.inliers;
    c.model = v.check.model;
    c.geometric = v.check.verified;
    c.streak = v.streak;
    c.verified = v.accepted;
    c.accepted = v.accepted;
  }
  s.previous = std::move(current);
  verify += Seconds(check_start);
  r.verify_seconds = verify;
  return r;
}

void OnlineDetector::AddToMap(const cv::Mat& rows) {
  State& s = *state_;
  if (s.verifier)
    throw InputError(
        "OnlineDetector::AddToMap: verification is on (OnlineOptions::"
        "verification.enabled) and needs each frame's image: add the frames with "
        "AddFrame");
  if (rows.empty()) return;
  const RowsByChannel split = s.Split(rows, "map rows");
  s.ThrowIfDamaged(false);
  s.Append(split);
  s.Appended(rows.rows);
  s.EnsureUnits();
  if (IncrementalIndex* index = s.Index())
    index->Update(s.Size() - s.options.exclusion, /*background=*/false);
}

cv::Mat OnlineDetector::DescribeFrames(const std::vector<cv::Mat>& images,
                                       const std::vector<std::string>& names) const {
  const State& s = *state_;
  if (!names.empty() && names.size() != images.size())
    throw std::invalid_argument("OnlineDetector::DescribeFrames: " + std::to_string(names.size()) +
                                " names for " + std::to_string(images.size()) + " images");
  std::string size = s.frame_size;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string mine = SizeText(images[i].size());
    CheckFrameSize(ImageName(names, static_cast<int>(i)), mine, size);
    size = mine;
  }
  std::vector<const FrameDescriber*> describers;
  for (const State::Channel& c : s.channels) describers.push_back(c.describer.frame.get());
  return s.Pack(DescribeNamed(describers, images, names, 0));
}

void OnlineDetector::AddImagesToMap(const std::vector<cv::Mat>& images,
                                    const std::vector<std::string>& names) {
  const cv::Mat rows = DescribeFrames(images, names);
  if (names.empty())
    AddToMap(rows);
  else
    AddToMap(rows, names);
  if (!images.empty()) state_->frame_size = SizeText(images.front().size());
}

void OnlineDetector::AddToMap(const cv::Mat& rows, const std::vector<std::string>& names) {
  if (names.size() != static_cast<size_t>(rows.rows))
    throw InputError("OnlineDetector::AddToMap: " + std::to_string(names.size()) + " names for " +
                     std::to_string(rows.rows) + " rows; expected one each");
  State& s = *state_;
  const int before = Size();
  AddToMap(rows);
  s.files.resize(static_cast<size_t>(before));
  s.files.insert(s.files.end(), names.begin(), names.end());
}

OnlineResult OnlineDetector::AddDescriptor(const cv::Mat& row) {
  State& s = *state_;
  const RowsByChannel split = s.Split(row, "descriptor row", "1");
  if (s.verifier)
    throw InputError(
        "OnlineDetector::AddDescriptor: verification is on (OnlineOptions::"
        "verification.enabled) and needs each frame's image: use AddFrame");
  s.ThrowIfDamaged(false);
  return s.Search(split);
}

namespace {

// The columns of every frame [0, end) of the map (sessions cut at `end`).
Columns ColumnsUpTo(const std::vector<MapSession>& sessions, int end) {
  Columns c;
  for (const MapSession& m : sessions) {
    if (m.first >= end) break;
    const int n = std::min(m.count, end - m.first);
    if (n <= 0) continue;
    c.starts.push_back(c.count);
    c.ranges.emplace_back(m.first, n);
    c.count += n;
  }
  return c;
}

}  // namespace

OnlineResult OnlineDetector::State::Search(const RowsByChannel& row) {
  State& s = *this;
  const auto start = Clock::now();
  s.Append(row);
  s.Appended(1);
  OnlineResult r;
  r.frame = s.Size() - 1;
  r.session = static_cast<int>(s.sessions.size()) - 1;
  const int q = r.frame;
  // Frames j <= q - exclusion of its own session, and every frame of the earlier ones.
  const int first = s.sessions.back().first;
  const int searchable = std::max(first, q - s.options.exclusion + 1);
  const int qi = q - first;  // the frame within its traversal
  // The best candidates of the traversal's earlier frames (-1 for those not searched).
  s.answers.resize(static_cast<size_t>(qi), -1);
  if (searchable > 0) {
    s.EnsureUnits();
    if (IncrementalIndex* index = s.Index()) index->Update(searchable);
    // The rows of the map hold this traversal's rows too: frames first .. q.
    RowsByChannel mine;
    for (const State::Channel& c : s.channels) mine.push_back(c.rows->Rows());
    std::vector<std::pair<double, int>> scored;
    double* largest = s.UnitFixed() ? nullptr : &s.unit;
    if (s.Exact()) {
      // The running sums: the previous row of this traversal over as many columns, or one
      // fewer; else they start again from the L - 1 frames before (fewer at its start).
      const Columns columns = ColumnsUpTo(s.sessions, searchable);
      const int L = s.options.sequence_length;
      const bool continues =
          s.running_last == q - 1 && s.running.Rows() > 0 && q - 1 >= first &&
          (columns.count == s.running_columns || columns.count == s.running_columns + 1);
      int from = q;
      if (!continues) {
        s.running.Restart();
        from = std::max(first, q - L + 1);
      }
      cv::Mat1f d = s.SingleFrameRows(mine, from, q + 1, columns, s.units);
      for (int i = 0; i < d.rows; ++i) {
        if (largest != nullptr) *largest = std::max(*largest, LargestFinite(d.row(i)));
        s.running.Push(d.ptr<float>(i), columns.count, columns.starts);
      }
      s.running_last = q;
      s.running_columns = columns.count;
      const float* sums = d.ptr<float>(d.rows - 1);
      scored.reserve(static_cast<size_t>(columns.count));
      for (int c = 0; c < columns.count; ++c)
        if (std::isfinite(sums[c])) scored.emplace_back(sums[c], c);
      for (auto& [distance, frame] : scored) frame = columns.Frame(frame);
    } else {
      s.running_last = -1;
      const IncrementalIndex& index = *s.Index();
      const cv::Mat key = mine[static_cast<size_t>(s.indexed)].row(q);
      for (const int j : index.Candidates(key, searchable, &r.approximate))
        scored.emplace_back(s.CellDistance(mine, q, first, j, s.units, largest), j);
    }
    s.Choose(scored, s.unit, r);
    s.Confirm(r, qi, s.answers);
  } else {
    s.answers.push_back(-1);
  }
  r.search_seconds = Seconds(start);
  return r;
}

void OnlineDetector::State::Choose(std::vector<std::pair<double, int>>& scored, double unit_now,
                                   OnlineResult& r) const {
  const State& s = *this;
  // The candidates returned: the k best, or with verification the k best at distinct places
  // (the choice of Test_OpenABLE's verification, DistinctBest).
  std::vector<std::size_t> chosen;
  if (s.verifier) {
    std::vector<std::pair<float, int>> cells;
    for (const auto& [d, j] : scored) cells.emplace_back(static_cast<float>(d), j);
    chosen = DistinctBest(cells, s.options.verification.candidates, s.options.score.window);
  } else {
    const size_t k = std::min(scored.size(), static_cast<size_t>(s.options.candidates));
    std::partial_sort(scored.begin(), scored.begin() + k, scored.end());
    for (size_t i = 0; i < k; ++i) chosen.push_back(i);
  }
  // The ratio's rivals: every candidate scored.
  std::vector<std::pair<float, int>> rivals;
  if (s.options.score.kind == MatchScore::kRatio)
    for (const auto& [d, j] : scored) rivals.emplace_back(static_cast<float>(d), j);
  const double scale = s.options.sequence_length * unit_now;
  const double threshold = s.options.Threshold();
  for (const size_t i : chosen) {
    LoopCandidate c;
    c.frame = scored[i].second;
    c.session = s.SessionOf(c.frame);
    c.session_frame = c.frame - s.sessions[static_cast<std::size_t>(c.session)].first;
    c.distance = scored[i].first;
    c.normalized = scale > 0 ? c.distance / scale : 0.0;
    c.score = s.options.score.kind == MatchScore::kRatio
                  ? ScoreOfCandidate(rivals, i, s.options.score)
                  : c.normalized;
    c.accepted = c.score <= threshold && !s.Unreliable();
    r.candidates.push_back(c);
  }
}

void OnlineDetector::State::Confirm(OnlineResult& r, int qi, std::vector<int>& answers) const {
  const State& s = *this;
  if (static_cast<int>(answers.size()) <= qi) answers.resize(static_cast<size_t>(qi) + 1, -1);
  answers[static_cast<size_t>(qi)] = r.candidates.empty() ? -1 : r.candidates.front().frame;
  if (s.verifier) return;  // verification decides
  const AgreementOptions agreement = s.Agreement();
  for (LoopCandidate& c : r.candidates) {
    // The chain of partners back from qi (matching/agreement.h), each agreeing with the one
    // after it, within one session of the map.
    int found = 0, from = qi, from_answer = c.frame;
    for (int p = AgreementPartner(qi, qi + 1, agreement); p >= 0 && found < agreement.partners;
         p = AgreementPartner(p, p + 1, agreement)) {
      const int a = answers[static_cast<size_t>(p)];
      if (a < 0 || s.SessionOf(a) != s.SessionOf(from_answer) ||
          !AnswersAgree(p, a, from, from_answer, agreement))
        break;
      ++found;
      from = p;
      from_answer = a;
    }
    c.confirmed = found == agreement.partners;
    if (s.options.consistency > 0) c.accepted = c.accepted && c.confirmed;
  }
}

// ---- Sessions and queries ------------------------------------------------------------------

void OnlineDetector::StartSession(const std::string& name, const std::string& time) {
  State& s = *state_;
  CheckSessionName(name, "OnlineDetector::StartSession: session name");
  if (!s.sessions.empty() && s.sessions.back().count == 0) s.sessions.pop_back();
  for (const MapSession& m : s.sessions)
    if (m.name == name)
      throw InputError("OnlineDetector::StartSession: the map already has a session named " +
                       Quoted(name) + " (frames " + std::to_string(m.first) + " to " +
                       std::to_string(m.first + m.count - 1) + "); expected a new name");
  if (!time.empty()) CheckSessionTime(time, "OnlineDetector::StartSession: session time");
  s.sessions.push_back({name, time.empty() ? MapTimeNow() : time, Size(), 0});
  s.answers.clear();
  s.running_last = -1;
}

const std::vector<MapSession>& OnlineDetector::Sessions() const { return state_->sessions; }

int OnlineDetector::SessionOf(int frame) const {
  if (frame < 0 || frame >= Size())
    throw InputError("OnlineDetector::SessionOf(" + std::to_string(frame) +
                     "): expected a frame "
                     "of the map, 0 to " +
                     std::to_string(Size() - 1));
  return state_->SessionOf(frame);
}

const std::string& OnlineDetector::FrameSize() const { return state_->frame_size; }

void OnlineDetector::CheckMap() const { state_->ThrowIfDamaged(true); }

std::vector<OnlineResult> OnlineDetector::Query(const cv::Mat& rows,
                                                const std::vector<std::string>& sessions,
                                                const std::function<void(int, int)>& progress,
                                                QueryMatrix* matrix) const {
  const State& s = *state_;
  if (s.verifier)
    throw InputError(
        "OnlineDetector::Query: verification is on (OnlineOptions::verification."
        "enabled) and needs each query's image and features: add the frames with "
        "AddFrame, or query with a detector without verification");
  const RowsByChannel queries = s.Split(rows, "query rows");
  s.ThrowIfDamaged(false);
  // The sessions searched, and whether their frames are few enough to scan exactly.
  std::vector<char> allowed(s.sessions.size(), sessions.empty() ? 1 : 0);
  std::int64_t allowed_frames = 0;
  for (const std::string& name : sessions) {
    std::size_t i = 0;
    while (i < s.sessions.size() && s.sessions[i].name != name) ++i;
    if (i == s.sessions.size()) {
      std::string names;
      for (const MapSession& m : s.sessions) names += (names.empty() ? "" : ", ") + m.name;
      throw InputError("session " + Quoted(name) +
                       " is not in the map; its sessions: " + (names.empty() ? "none" : names));
    }
    if (!allowed[i]) allowed_frames += s.sessions[i].count;
    allowed[i] = 1;
  }
  const int n = rows.rows, size = Size();
  std::vector<OnlineResult> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out[static_cast<size_t>(i)].frame = i;
  if (size == 0 || n == 0) return out;
  const std::vector<double> units = s.UnitsNow();
  double unit = s.unit;
  const bool exact = s.Exact() || (!sessions.empty() && allowed_frames <= s.options.exact_limit);
  if (exact) {
    // Every frame of the sessions searched: the single-frame rows of a block of queries at a
    // time (at most about 64 MB of them), their sums running down the diagonals.
    Columns columns;
    for (std::size_t k = 0; k < s.sessions.size(); ++k)
      if (allowed[k] && s.sessions[k].count > 0) {
        columns.starts.push_back(columns.count);
        columns.ranges.emplace_back(s.sessions[k].first, s.sessions[k].count);
        columns.count += s.sessions[k].count;
      }
    if (columns.count == 0) return out;
    if (matrix != nullptr) {
      matrix->frames.clear();
      for (const auto& [first, count] : columns.ranges)
        for (int j = first; j < first + count; ++j) matrix->frames.push_back(j);
      if (4.0 * n * columns.count <= static_cast<double>(matrix->max_bytes))
        matrix->sums.create(n, columns.count);
    }
    SequenceRowSums sums(s.options.sequence_length, SequencePartial::kScale);
    const int block = std::max(1, static_cast<int>(std::min<std::int64_t>(
                                      n, (64 << 20) / (4 * std::max(1, columns.count)))));
    const bool track = !s.UnitFixed();
    for (int a = 0; a < n; a += block) {
      CheckForInterrupt();
      const auto start = Clock::now();
      const int b = std::min(n, a + block);
      cv::Mat1f d = s.SingleFrameRows(queries, a, b, columns, units);
      if (track) unit = std::max(unit, LargestFinite(d));
      for (int i = a; i < b; ++i) {
        float* row = d.ptr<float>(i - a);
        sums.Push(row, columns.count, columns.starts);
        if (matrix != nullptr && !matrix->sums.empty())
          std::memcpy(matrix->sums.ptr<float>(i), row, sizeof(float) * columns.count);
        std::vector<std::pair<double, int>> scored;
        scored.reserve(static_cast<size_t>(columns.count));
        for (int c = 0; c < columns.count; ++c)
          if (std::isfinite(row[c])) scored.emplace_back(row[c], c);
        for (auto& [distance, frame] : scored) frame = columns.Frame(frame);
        s.Choose(scored, unit, out[static_cast<size_t>(i)]);
      }
      const double each = Seconds(start) / (b - a);
      for (int i = a; i < b; ++i) out[static_cast<size_t>(i)].search_seconds = each;
      if (progress) progress(b, n);
    }
  } else {
    // The index's candidates of each query, each scored by its sequence sum from the rows.
    if (matrix != nullptr) {
      matrix->sums.release();
      matrix->frames.clear();
    }
    std::atomic<int> done{0};
    std::mutex told;
    ParallelFor(n, 0, [&](int i) {
      const auto start = Clock::now();
      OnlineResult& r = out[static_cast<std::size_t>(i)];
      const cv::Mat key = queries[static_cast<size_t>(s.indexed)].row(i);
      double largest = unit;
      std::vector<std::pair<double, int>> scored;
      for (const int j : s.Index()->Candidates(key, size, &r.approximate))
        if (allowed[static_cast<std::size_t>(s.SessionOf(j))])
          scored.emplace_back(s.CellDistance(queries, i, 0, j, units, &largest), j);
      s.Choose(scored, s.UnitFixed() ? s.unit : largest, r);
      r.search_seconds = Seconds(start);
      const int finished = ++done;
      if (progress && (finished % 256 == 0 || finished == n) && told.try_lock()) {
        progress(finished, n);
        told.unlock();
      }
    });
  }
  // The consistency runs down the queries in order: each needs the answers before it.
  std::vector<int> answers;
  for (int i = 0; i < n; ++i) s.Confirm(out[static_cast<size_t>(i)], i, answers);
  return out;
}

std::vector<OnlineResult> OnlineDetector::QueryImages(
    const std::vector<cv::Mat>& images, const std::vector<std::string>& sessions) const {
  return Query(DescribeFrames(images), sessions);
}

// ---- Saved maps ----------------------------------------------------------------------------

namespace {

std::string Exact(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

// Whether the descriptors of `o` (searched or kept) include a network (ONNX).
bool UsesNetwork(const OnlineOptions& o) {
  for (const std::string& list : {o.descriptor.name, o.kept_descriptors})
    if (!list.empty())
      for (const std::string& n : DescriptorList(list))
        if (n == "ONNX") return true;
  return false;
}

std::string Numbers(const std::vector<double>& values) {
  std::string out;
  for (const double v : values) out += (out.empty() ? "" : ",") + Exact(v);
  return out;
}

// The settings that make the rows: a map made with others cannot be searched with this
// detector's rows. (The descriptors themselves are the map's "channels".)
std::vector<std::pair<std::string, std::string>> DescriptionSettings(const OnlineOptions& o) {
  std::vector<std::pair<std::string, std::string>> out = {
      {"description", EnumName(o.description)},
      {"patch_size", std::to_string(o.descriptor.patch_size)},
      {"ldb_bits", std::to_string(o.descriptor.ldb_bits)},
      {"sad_patch", std::to_string(o.descriptor.sad_patch)},
      {"grid_x", std::to_string(o.grid_x)},
      {"grid_y", std::to_string(o.grid_y)}};
  // A network: how frames are prepared for it (its weights are checked by their digest,
  // "model_weights", and its file may move: "model_path" is where it was).
  if (UsesNetwork(o))
    out.insert(out.end(), {{"model_input_size", o.descriptor.model_input_size},
                           {"model_channels", o.descriptor.model_channels},
                           {"model_mean", o.descriptor.model_mean},
                           {"model_std", o.descriptor.model_std},
                           {"model_normalize", o.descriptor.model_normalize ? "1" : "0"}});
  return out;
}

// The settings that make the index blocks: with others, the saved blocks are rebuilt.
std::vector<std::pair<std::string, std::string>> IndexSettings(const OnlineOptions& o) {
  const ApproximateOptions& a = o.approximate;
  return {{"exclusion", std::to_string(o.exclusion)},
          {"exact_limit", std::to_string(o.exact_limit)},
          {"block_frames", std::to_string(o.block_frames)},
          {"engine", ParseApproximateEngine(a.engine, "OnlineOptions.approximate.engine")},
          {"hnsw_m", std::to_string(a.hnsw_m)},
          {"hnsw_ef_construction", std::to_string(a.hnsw_ef_construction)},
          {"ivf_lists", std::to_string(a.ivf_lists)},
          {"lsh_tables", std::to_string(a.lsh_tables)},
          {"lsh_key_bits", std::to_string(a.lsh_key_bits)},
          {"lsh_probe_level", std::to_string(a.lsh_probe_level)},
          {"kd_trees", std::to_string(a.kd_trees)},
          {"seed", std::to_string(a.seed)}};
}

std::vector<std::pair<std::string, std::string>> FeatureSettings(const OnlineOptions& o) {
  if (!o.verification.enabled) return {{"features", "none"}};
  return {{"features", EnumName(o.verification.features)},
          {"max_features", std::to_string(o.verification.max_features)}};
}

// The search settings, as the map keeps those it searches with ("search_" before each key) and
// those Tune chose ("tuned_"). The threshold as given (< 0: the score's default).
std::vector<std::pair<std::string, std::string>> SearchSettings(const OnlineOptions& o) {
  return {{"descriptor", o.descriptor.name},
          {"fusion_weights", Numbers(o.fusion_weights)},
          {"contrast_enhancement", o.contrast.enabled ? "1" : "0"},
          {"contrast_window", std::to_string(o.contrast.window)},
          {"sequence_length", std::to_string(o.sequence_length)},
          {"score", EnumName(o.score.kind)},
          {"score_window", std::to_string(o.score.window)},
          {"threshold", Exact(o.threshold)},
          {"consistency", std::to_string(o.consistency)}};
}

// Whether two options search alike (SearchSettings; the descriptors' names in any case).
bool SameSearch(const OnlineOptions& a, const OnlineOptions& b) {
  auto x = SearchSettings(a), y = SearchSettings(b);
  x[0].second = JoinStrings(ChannelNames(a.descriptor.name, ""), "+");
  y[0].second = JoinStrings(ChannelNames(b.descriptor.name, ""), "+");
  x[7].second = Exact(a.Threshold());
  y[7].second = Exact(b.Threshold());
  return x == y;
}

}  // namespace

void OnlineDetector::SaveMap(const std::string& path) {
  State& s = *state_;
  // A map loaded damaged is not written out again as if it were sound.
  s.ThrowIfDamaged(true);
  FinishMerges();
  const State::Channel& first = s.channels.front();
  MapFile map;
  map.settings = {{"openable", kVersion},
                  {"frames", std::to_string(Size())},
                  {"row_width", std::to_string(first.width)},
                  {"row_type", first.type == CV_8U ? "CV_8U" : "CV_32F"},
                  {"unit", Exact(s.unit)},
                  {"frame_size", s.frame_size},
                  {"descriptor", s.options.descriptor.name}};
  std::string widths, types;
  for (const State::Channel& c : s.channels) {
    widths += (widths.empty() ? "" : " ") + std::to_string(c.width);
    types += (types.empty() ? "" : " ") + std::string(c.type == CV_8U ? "CV_8U" : "CV_32F");
  }
  map.settings.insert(map.settings.end(), {{"channels", JoinStrings(s.ChannelList(), " ")},
                                           {"channel_widths", widths},
                                           {"channel_types", types},
                                           {"indexed_channel", std::to_string(s.indexed)}});
  for (const auto& list :
       {DescriptionSettings(s.options), IndexSettings(s.options), FeatureSettings(s.options)})
    map.settings.insert(map.settings.end(), list.begin(), list.end());
  for (const State::Channel& c : s.channels)
    if (c.describer.descriptor->Name() == "ONNX")
      map.settings.insert(map.settings.end(),
                          {{"model_path", AbsoluteModelPath(s.options.descriptor.model_path)},
                           {"model_weights", c.describer.descriptor->Fingerprint()}});
  for (const auto& [key, value] : SearchSettings(s.options))
    map.settings.emplace_back("search_" + key, value);
  if (s.tuning.tuned) {
    const MapTuning& t = s.tuning;
    map.settings.insert(map.settings.end(), {{"tuned", t.reliable ? "reliable" : "unreliable"},
                                             {"tuned_reference", t.reference},
                                             {"tuned_query", t.query},
                                             {"tuned_time", t.time},
                                             {"tuned_chosen", t.chosen},
                                             {"tuned_consistency_figure", Exact(t.consistency)},
                                             {"tuned_distinctiveness", Exact(t.distinctiveness)},
                                             {"tuned_agreement", Exact(t.agreement)},
                                             {"tuned_min_consistency", Exact(t.min_consistency)},
                                             {"tuned_fusion_units", Numbers(t.units)},
                                             {"tuned_contrast_shift", Exact(t.shift)},
                                             {"tuned_candidates", t.candidates_json}});
    for (const auto& [key, value] : SearchSettings(t.search))
      map.settings.emplace_back("tuned_" + key, value);
  }
  map.sessions = s.sessions;
  IncrementalIndex* index = s.Index();
  if (index != nullptr) map.blocks = index->SaveBlocks();
  map.rows = first.rows->Rows();
  for (size_t c = 1; c < s.channels.size(); ++c)
    map.more_rows.push_back(s.channels[c].rows->Rows());
  map.frame_files = s.files;
  if (!map.frame_files.empty()) map.frame_files.resize(static_cast<size_t>(Size()));
  map.has_features = s.verifier != nullptr;
  if (map.has_features) map.features = s.features;
  WriteMapFile(path, map);
}

namespace {

std::vector<double> ParseNumbers(const MapFile& map, const std::string& key,
                                 const std::string& path) {
  std::vector<double> out;
  const std::string text = map.Setting(key);
  for (const std::string& part : SplitTrimmed(text, ',')) {
    if (text.empty()) break;
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(v) || v < 0)
      throw InputError(path + ": setting " + Quoted(key) + " of the map is " + Quoted(text) +
                       ": expected numbers >= 0 separated by commas");
    out.push_back(v);
  }
  return out;
}

double ParseNumber(const MapFile& map, const std::string& key, const std::string& path) {
  const std::string text = map.Setting(key);
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    throw InputError(path + ": setting " + Quoted(key) + " of the map is " + Quoted(text) +
                     ": expected a number");
  return v;
}

template <typename T>
void ParseWhole(const MapFile& map, const std::string& key, const std::string& path, T& field) {
  const std::string text = map.Setting(key);
  try {
    std::size_t used = 0;
    const long long v = std::stoll(text, &used);
    const auto lo = static_cast<long double>(std::numeric_limits<T>::min());
    const auto hi = static_cast<long double>(std::numeric_limits<T>::max());
    if (used == text.size() && v >= lo && v <= hi) {
      field = static_cast<T>(v);
      return;
    }
  } catch (const std::exception&) {
  }
  throw InputError(path + ": setting \"" + key + "\" of the map is " + Quoted(text) +
                   ": expected a whole number");
}

// The channel whose index finds candidates ("indexed_channel"): -1 (none) or one of the
// map's `channels`, else one line (an index beyond them would be read out of bounds).
void ParseIndexedChannel(const MapFile& map, const std::string& path, int channels, int& indexed) {
  ParseWhole(map, "indexed_channel", path, indexed);
  if (indexed < -1 || indexed >= channels)
    throw InputError(path + ": setting \"indexed_channel\" of the map is " +
                     std::to_string(indexed) + "; expected -1 (none) to " +
                     std::to_string(channels - 1) + " (its " + std::to_string(channels) +
                     " descriptors)");
}

// The descriptors of a map: "channels" (format 3), else its one "descriptor".
std::vector<std::string> MapChannels(const MapFile& map) {
  std::vector<std::string> out;
  std::istringstream in(map.Setting("channels"));
  for (std::string name; in >> name;) out.push_back(name);
  if (out.empty()) out = ChannelNames(map.Setting("descriptor"), "");
  return out;
}

// The search settings a map keeps under `prefix` ("search_", "tuned_") over `o`.
void ReadSearch(const MapFile& map, const std::string& path, const std::string& prefix,
                OnlineOptions& o) {
  o.descriptor.name = map.Setting(prefix + "descriptor");
  o.fusion_weights = ParseNumbers(map, prefix + "fusion_weights", path);
  o.contrast.enabled = map.Setting(prefix + "contrast_enhancement") == "1";
  ParseWhole(map, prefix + "contrast_window", path, o.contrast.window);
  ParseWhole(map, prefix + "sequence_length", path, o.sequence_length);
  o.score.kind = ParseEnum<MatchScore>(map.Setting(prefix + "score"),
                                       path + ": setting \"" + prefix + "score\"");
  ParseWhole(map, prefix + "score_window", path, o.score.window);
  o.threshold = ParseNumber(map, prefix + "threshold", path);
  ParseWhole(map, prefix + "consistency", path, o.consistency);
}

MapTuning ReadTuning(const MapFile& map, const std::string& path) {
  MapTuning t;
  const std::string verdict = map.Setting("tuned");
  if (verdict.empty()) return t;
  if (verdict != "reliable" && verdict != "unreliable")
    throw InputError(path + ": setting \"tuned\" of the map is " + Quoted(verdict) +
                     ": expected reliable or unreliable");
  t.tuned = true;
  t.reliable = verdict == "reliable";
  t.reference = map.Setting("tuned_reference");
  t.query = map.Setting("tuned_query");
  t.time = map.Setting("tuned_time");
  t.chosen = map.Setting("tuned_chosen");
  t.consistency = ParseNumber(map, "tuned_consistency_figure", path);
  t.distinctiveness = ParseNumber(map, "tuned_distinctiveness", path);
  t.agreement = ParseNumber(map, "tuned_agreement", path);
  t.min_consistency = ParseNumber(map, "tuned_min_consistency", path);
  t.units = ParseNumbers(map, "tuned_fusion_units", path);
  t.shift = ParseNumber(map, "tuned_contrast_shift", path);
  t.candidates_json = map.Setting("tuned_candidates");
  ReadSearch(map, path, "tuned_", t.search);
  return t;
}

// Checks that the map read from `path` can join a detector of `options` (description
// settings, descriptors, rows, features), else one InputError naming the path and what
// differs. Returns the map's unit (float rows: the largest single-frame distance it had seen).
double CheckMapFits(const MapFile& map, const std::string& path, const OnlineOptions& options,
                    const std::vector<std::string>& channels, const std::vector<int>& widths,
                    const std::vector<int>& types, const PairVerifier* verifier, double unit) {
  const std::string what = "the map was made with ";
  // Settings the map must share with this detector, else one line naming the first that differs.
  const auto require_same = [&](const std::vector<std::pair<std::string, std::string>>& settings,
                                const std::string& mine, const std::string& expected) {
    for (const auto& [key, value] : settings) {
      // Maps of format 2 did not name the SAD patch (they could not hold SAD rows).
      if (key == "sad_patch" && map.Setting(key).empty()) continue;
      if (map.Setting(key) != value)
        throw InputError(path + ": " + what + key + " = " + map.Setting(key) + "; this detector " +
                         mine + " " + key + " = " + value + " (" + expected + ")");
    }
  };
  const std::vector<std::string> theirs = MapChannels(map);
  if (theirs != channels)
    throw InputError(path + ": " + what + "the descriptors " + JoinStrings(theirs, "+") +
                     "; this detector has " + JoinStrings(channels, "+") +
                     " (expected the same descriptors: MapOptions gives a map's own)");
  require_same(DescriptionSettings(options), "has",
               "expected the same description settings: description, patch_size, ldb_bits, "
               "sad_patch, grid_x, grid_y");
  std::vector<const cv::Mat*> rows{&map.rows};
  for (const cv::Mat& m : map.more_rows) rows.push_back(&m);
  if (rows.size() != channels.size())
    throw InputError(path + ": the map holds the rows of " + std::to_string(rows.size()) +
                     " descriptors; expected " + std::to_string(channels.size()));
  for (size_t c = 0; c < rows.size(); ++c) {
    if (rows[c]->cols != widths[c] || rows[c]->depth() != types[c])
      throw InputError(path + ": the map's " + channels[c] + " rows are " +
                       std::to_string(rows[c]->cols) + " " + cv::typeToString(rows[c]->type()) +
                       "; expected " + std::to_string(widths[c]) + " " +
                       cv::typeToString(types[c]) + " (" + channels[c] + ")");
    if (types[c] == CV_32F && !rows[c]->empty() && !cv::checkRange(*rows[c]))
      throw InputError(path + ": the map's rows hold a value that is not finite");
  }
  if (verifier) {
    require_same(FeatureSettings(options), "verifies with",
                 "expected a map saved by a detector with the same verification features");
    if (!map.has_features || map.features.size() != static_cast<size_t>(map.rows.rows))
      throw InputError(path +
                       ": the map holds no local features; expected a map saved by a "
                       "detector with verification enabled");
    // The matcher compares them with the descriptors of later frames.
    const int fwidth = verifier->DescriptorWidth(), ftype = verifier->DescriptorType();
    for (size_t i = 0; i < map.features.size(); ++i) {
      const cv::Mat& d = map.features[i].descriptors;
      if (!d.empty() && (d.cols != fwidth || d.type() != ftype))
        throw InputError(path + ": the local features of frame " + std::to_string(i) +
                         " have descriptors of " + std::to_string(d.cols) + " " +
                         cv::typeToString(d.type()) + "; expected " + std::to_string(fwidth) + " " +
                         cv::typeToString(ftype) + " (" + map.Setting("features") + ")");
    }
  }
  if (map.Setting("unit") != "") {
    const std::string text = map.Setting("unit");
    char* end = nullptr;
    const double u = std::strtod(text.c_str(), &end);
    if (*end != '\0' || !std::isfinite(u) || u < 0)
      throw InputError(path + ": setting \"unit\" of the map is \"" + text +
                       "\": expected a number >= 0");
    if (types.size() == 1 && types.front() == CV_32F) unit = u;
  }
  return unit;
}

}  // namespace

namespace {

// `f()`, its InputError naming `path` (the map's settings are checked by the same functions
// as options are, whose messages name the option alone).
template <typename F>
auto NamingMap(const std::string& path, F f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.find(path) != std::string::npos) throw;
    throw InputError(path + ": " + message);
  }
}

OnlineOptions ReadMapOptions(const std::string& path, const OnlineOptions& base);

}  // namespace

OnlineOptions MapOptions(const std::string& path, const OnlineOptions& base) {
  return NamingMap(path, [&] { return ReadMapOptions(path, base); });
}

namespace {

OnlineOptions ReadMapOptions(const std::string& path, const OnlineOptions& base) {
  MapReadOptions read;
  read.header_only = true;
  const MapFile map = ReadMapFile(path, read);
  OnlineOptions o = base;
  const std::vector<std::string> channels = MapChannels(map);
  o.descriptor.name = map.Setting("descriptor");
  std::vector<std::string> kept;
  const std::vector<std::string> searched = ChannelNames(o.descriptor.name, "");
  for (const std::string& c : channels)
    if (std::find(searched.begin(), searched.end(), c) == searched.end()) kept.push_back(c);
  o.kept_descriptors = JoinStrings(kept, "+");
  if (!o.fusion_weights.empty() && o.fusion_weights.size() != searched.size())
    o.fusion_weights.clear();
  o.description =
      ParseEnum<DescriptionType>(map.Setting("description"), path + ": setting \"description\"");
  ParseWhole(map, "patch_size", path, o.descriptor.patch_size);
  ParseWhole(map, "ldb_bits", path, o.descriptor.ldb_bits);
  if (!map.Setting("sad_patch").empty()) ParseWhole(map, "sad_patch", path, o.descriptor.sad_patch);
  if (Upper(o.descriptor.name) == "NPY") {
    // Rows given by a file (openable_map add --descriptors): their width and type.
    ParseWhole(map, "row_width", path, o.descriptor.given_width);
    o.descriptor.given_binary = map.Setting("row_type") == "CV_8U";
    if (o.description != DescriptionType::kGlobal)
      throw InputError(path +
                       ": the map's rows were given (descriptor NPY), one row a frame, "
                       "but its settings name the description " +
                       EnumName(o.description) + "; expected global");
    CreateDescriptor(o.descriptor);  // the width's bound, named by NamingMap
  }
  if (!map.Setting("model_weights").empty()) {
    // A network: its file as given (a copy moved elsewhere, checked by its weights' digest
    // when the map loads), else where the map was saved from.
    if (o.descriptor.model_path.empty()) o.descriptor.model_path = map.Setting("model_path");
    o.descriptor.model_input_size = map.Setting("model_input_size");
    o.descriptor.model_channels = map.Setting("model_channels");
    o.descriptor.model_mean = map.Setting("model_mean");
    o.descriptor.model_std = map.Setting("model_std");
    o.descriptor.model_normalize = map.Setting("model_normalize") != "0";
  }
  ParseWhole(map, "grid_x", path, o.grid_x);
  ParseWhole(map, "grid_y", path, o.grid_y);
  ParseWhole(map, "exclusion", path, o.exclusion);
  ParseWhole(map, "exact_limit", path, o.exact_limit);
  ParseWhole(map, "block_frames", path, o.block_frames);
  o.approximate.engine = map.Setting("engine");
  ParseWhole(map, "hnsw_m", path, o.approximate.hnsw_m);
  ParseWhole(map, "hnsw_ef_construction", path, o.approximate.hnsw_ef_construction);
  ParseWhole(map, "ivf_lists", path, o.approximate.ivf_lists);
  ParseWhole(map, "lsh_tables", path, o.approximate.lsh_tables);
  ParseWhole(map, "lsh_key_bits", path, o.approximate.lsh_key_bits);
  ParseWhole(map, "lsh_probe_level", path, o.approximate.lsh_probe_level);
  ParseWhole(map, "kd_trees", path, o.approximate.kd_trees);
  ParseWhole(map, "seed", path, o.approximate.seed);
  // The search: Tune's choice, else the one the map was saved with (format 3), else base's.
  if (!map.Setting("tuned").empty())
    ReadSearch(map, path, "tuned_", o);
  else if (!map.Setting("search_sequence_length").empty())
    ReadSearch(map, path, "search_", o);
  try {
    o.Check();
  } catch (const InputError& e) {
    throw InputError(path + ": the map's settings are not valid options: " + e.what());
  }
  return o;
}

}  // namespace

OnlineDetector::LoadedMap OnlineDetector::LoadMap(const std::string& path,
                                                  const MapReadOptions& read) {
  return NamingMap(path, [&] { return LoadMapNamed(path, read); });
}

OnlineDetector::LoadedMap OnlineDetector::LoadMapNamed(const std::string& path,
                                                       const MapReadOptions& read) {
  State& s = *state_;
  if (Size() != 0)
    throw InputError("OnlineDetector::LoadMap(\"" + path + "\"): the detector holds " +
                     std::to_string(Size()) +
                     " frames; expected an empty detector (load the "
                     "map before adding frames)");
  MapFile map = ReadMapFile(path, read);
  // The detector's descriptors in the map's order (the same set), its index on the map's.
  std::vector<std::string> mine = s.ChannelList(), theirs = MapChannels(map);
  std::vector<std::string> a = mine, b = theirs;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  if (a == b && mine != theirs) {
    int indexed = -1;
    ParseIndexedChannel(map, path, static_cast<int>(theirs.size()), indexed);
    s.Build(s.options, theirs, indexed);
    s.SetSearch();
  } else if (a == b && !map.Setting("indexed_channel").empty()) {
    int indexed = -1;
    ParseIndexedChannel(map, path, static_cast<int>(theirs.size()), indexed);
    if (indexed != s.indexed) {
      s.Build(s.options, theirs, indexed);
      s.SetSearch();
    }
  }
  std::vector<int> widths, types;
  for (const State::Channel& c : s.channels) widths.push_back(c.width), types.push_back(c.type);
  // A network's weights first: other weights are also what makes rows of another width.
  for (const State::Channel& c : s.channels)
    if (c.describer.descriptor->Name() == "ONNX" &&
        c.describer.descriptor->Fingerprint() != map.Setting("model_weights"))
      throw InputError(path + ": the map was made with the network " +
                       Quoted(map.Setting("model_path")) + " of weights " +
                       Quoted(map.Setting("model_weights")) + "; Model_path " +
                       Quoted(s.options.descriptor.model_path) + " holds weights " +
                       Quoted(c.describer.descriptor->Fingerprint()) +
                       " (expected the same model file: give Model_path of a copy of it)");
  const double unit =
      CheckMapFits(map, path, s.options, s.ChannelList(), widths, types, s.verifier.get(), s.unit);
  if (map.frame_files.size() != 0 && map.frame_files.size() != static_cast<size_t>(map.rows.rows))
    throw InputError(path + ": the map names the files of " +
                     std::to_string(map.frame_files.size()) + " frames; expected its " +
                     std::to_string(map.rows.rows));
  LoadedMap out;
  out.frames = map.rows.rows;
  for (const auto& [key, value] : IndexSettings(s.options))
    if (map.Setting(key) != value) {
      out.rebuilt = true;
      out.reason = "the map was made with " + key + " = " + map.Setting(key) +
                   ", this detector has " + value;
      break;
    }
  const int searchable = map.rows.rows - s.options.exclusion;
  std::vector<const cv::Mat*> rows{&map.rows};
  for (const cv::Mat& m : map.more_rows) rows.push_back(&m);
  for (size_t c = 0; c < s.channels.size(); ++c) {
    IncrementalIndex& index = *s.channels[c].rows;
    const bool with_blocks = static_cast<int>(c) == s.indexed && !out.rebuilt;
    try {
      index.Restore(*rows[c],
                    with_blocks ? map.blocks : std::vector<IncrementalIndex::SavedBlock>{},
                    map.mapping);
    } catch (const std::invalid_argument& e) {
      throw InputError(path + ": " + e.what());
    }
    if (static_cast<int>(c) == s.indexed && out.rebuilt)
      index.Update(searchable, /*background=*/false);
  }
  if (s.UnitFixed() == false && s.channels.size() == 1) s.unit = unit;
  if (s.verifier) s.features = std::move(map.features);
  s.sessions = std::move(map.sessions);
  s.files = std::move(map.frame_files);
  s.frame_size = map.Setting("frame_size");
  s.tuning = ReadTuning(map, path);
  s.uses_tuning = s.tuning.tuned && SameSearch(s.options, s.tuning.search);
  if (s.uses_tuning) {
    s.units = s.tuning.units;
    s.shift = s.tuning.shift;
  }
  s.EnsureUnits();
  s.map_path = path;
  s.map_check = map.check;
  out.blocks = Blocks();
  return out;
}

void OnlineDetector::AppendMap(const std::string& path) {
  NamingMap(path, [&] { AppendMapNamed(path); });
}

void OnlineDetector::AppendMapNamed(const std::string& path) {
  State& s = *state_;
  s.ThrowIfDamaged(true);
  // Its rows are copied into this map: checked before they are.
  MapFile map = ReadMapFile(path, {/*in_place=*/true, /*check_in_background=*/false});
  std::vector<int> widths, types;
  for (const State::Channel& c : s.channels) widths.push_back(c.width), types.push_back(c.type);
  const double unit =
      CheckMapFits(map, path, s.options, s.ChannelList(), widths, types, s.verifier.get(), s.unit);
  const std::string size = map.Setting("frame_size");
  if (!size.empty() && !s.frame_size.empty() && size != s.frame_size)
    throw InputError(path + ": the map's frames are " + size + "; this map's are " + s.frame_size +
                     " (expected frames of one camera at one size)");
  for (const MapSession& m : map.sessions)
    for (const MapSession& mine : s.sessions)
      if (m.name == mine.name && mine.count > 0)
        throw InputError(path + ": both maps have a session named " + Quoted(m.name) +
                         "; expected maps of distinct sessions (each traversal once)");
  if (map.rows.rows == 0) return;
  const int first = Size();
  if (!s.sessions.empty() && s.sessions.back().count == 0) s.sessions.pop_back();
  RowsByChannel rows{map.rows};
  for (const cv::Mat& m : map.more_rows) rows.push_back(m);
  s.Append(rows);
  if (!s.files.empty() || !map.frame_files.empty()) {
    s.files.resize(static_cast<size_t>(first));
    if (map.frame_files.empty()) map.frame_files.resize(static_cast<size_t>(map.rows.rows));
    s.files.insert(s.files.end(), map.frame_files.begin(), map.frame_files.end());
  }
  for (MapSession m : map.sessions) {
    m.first += first;
    s.sessions.push_back(std::move(m));
  }
  if (s.frame_size.empty()) s.frame_size = size;
  if (!s.UnitFixed() && s.channels.size() == 1) s.unit = std::max(s.unit, unit);
  if (s.verifier)
    for (FrameFeatures& f : map.features) s.features.push_back(std::move(f));
  s.EnsureUnits();
  if (IncrementalIndex* index = s.Index())
    index->Update(Size() - s.options.exclusion, /*background=*/false);
}

const std::vector<std::string>& OnlineDetector::FrameFiles() const { return state_->files; }

// ---- Settings chosen from the data (OnlineDetector::Tune is in map_tuning.cc) ------------

cv::Mat OnlineDetector::ChannelRows(int channel) const {
  const State& s = *state_;
  if (channel < 0 || channel >= static_cast<int>(s.channels.size()))
    throw std::out_of_range("OnlineDetector::ChannelRows: no descriptor " +
                            std::to_string(channel));
  return s.channels[static_cast<size_t>(channel)].rows->Rows();
}

void OnlineDetector::UseTuning(const MapTuning& tuning) {
  State& s = *state_;
  if (!tuning.tuned) throw std::invalid_argument("OnlineDetector::UseTuning: not tuned");
  OnlineOptions search = s.options;
  const OnlineOptions& t = tuning.search;
  search.descriptor.name = t.descriptor.name;
  search.fusion_weights = t.fusion_weights;
  search.contrast = t.contrast;
  search.sequence_length = t.sequence_length;
  search.score = t.score;
  search.threshold = t.threshold;
  search.consistency = t.consistency;
  search.Check();
  const OnlineOptions before = s.options;
  s.options = search;
  try {
    s.SetSearch();
  } catch (...) {
    s.options = before;
    s.SetSearch();
    throw;
  }
  s.tuning = tuning;
  s.tuning.search = search;
  s.units = tuning.units;
  s.shift = tuning.shift;
  s.uses_tuning = true;
}

}  // namespace openable
