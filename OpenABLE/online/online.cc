#include "OpenABLE/online/online.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <cmath>
#include <mutex>
#include <sstream>
#include <utility>

#include <opencv2/core/utility.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/threading.h"
#include "OpenABLE/base/version.h"
#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/online/map_file.h"
#include "descriptors/registry.h"
#include "matching/search/incremental_index.h"
#include "matching/matrix.h"

namespace openable {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

void Require(bool ok, const std::string& field, const std::string& value,
             const std::string& expected) {
  if (!ok)
    throw InputError("OnlineOptions." + field + " = " + value + ": expected " + expected);
}

std::string SizeText(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

// A frame (`what`) of size `size` joining a map whose frames are `map_size` ("" = unknown).
void CheckFrameSize(const std::string& what, const std::string& size,
                    const std::string& map_size) {
  if (!map_size.empty() && size != map_size)
    throw InputError(what + " is " + size + "; the map's frames are " + map_size +
                     " (expected frames of one camera at one size)");
}

}  // namespace

void OnlineOptions::Check() const {
  Require(description == DescriptionType::kGlobal || description == DescriptionType::kGrid,
          "description", std::to_string(static_cast<int>(description)), "global or grid");
  Require(grid_x >= 1 && grid_x <= 64, "grid_x", std::to_string(grid_x), "1..64");
  Require(grid_y >= 1 && grid_y <= 64, "grid_y", std::to_string(grid_y), "1..64");
  Require(sequence_length >= 1 && sequence_length <= 1000, "sequence_length",
          std::to_string(sequence_length), "1..1000");
  Require(exclusion >= 1, "exclusion", std::to_string(exclusion),
          ">= 1 (frames between a frame and its earliest candidate)");
  Require(candidates >= 1 && candidates <= 1000, "candidates", std::to_string(candidates),
          "1..1000");
  Require(std::isfinite(threshold) && threshold >= 0, "threshold", std::to_string(threshold),
          "a number >= 0");
  Require(score == MatchScore::kDistance || score == MatchScore::kRatio, "score",
          std::to_string(static_cast<int>(score)), "distance or ratio");
  Require(score_window >= 0, "score_window", std::to_string(score_window),
          ">= 0 (frames on each side of a candidate that are not its rivals)");
  Require(exact_limit >= 0, "exact_limit", std::to_string(exact_limit), ">= 0");
  Require(block_frames >= 16, "block_frames", std::to_string(block_frames), ">= 16");
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

Describer MakeDescriber(const OnlineOptions& options) {
  options.Check();
  Describer out;
  out.descriptor = CreateDescriptor(options.descriptor);
  // A grey image per frame: descriptors of several channels (D-LDB: grey + disparity) need
  // stereo pairs.
  Require(out.descriptor->Channels() == 1, "descriptor", options.descriptor.name,
          "a single-camera descriptor (" + out.descriptor->Name() +
              " needs stereo pairs: use Test_OpenABLE with Camera_type 1)");
  out.frame = std::make_unique<FrameDescriber>(*out.descriptor, options.description,
                                               options.grid_x, options.grid_y, 1);
  return out;
}

namespace {

// Describes the grey image of a frame (GreyOfImage) with `describer`, checking its size.
void DescribeInto(const FrameDescriber& describer, const cv::Mat1b& grey, const std::string& what,
                  cv::Mat row) {
  const cv::Size need = describer.MinimumFrame();
  if (grey.cols < need.width || grey.rows < need.height)
    throw InputError(what + " is " + SizeText(grey.size()) + "; the grid needs at least " +
                     SizeText(need) + " pixels (grid_x by grid_y)");
  describer.Describe(grey, row);
}

}  // namespace

namespace {

// One row per image, described in parallel by `describer`; image i is named `names[i]` in
// messages (quoted, as a file), or "image i" when `names` is empty. The first image that
// cannot be described gives the error.
cv::Mat DescribeNamed(const FrameDescriber& describer, const std::vector<cv::Mat>& images,
                      const std::vector<std::string>& names, int threads) {
  const int n = static_cast<int>(images.size());
  cv::Mat rows(n, describer.RowWidth(), describer.RowType());
  if (n == 0) return rows;
  std::mutex mutex;
  int error_index = n;
  std::string error;
  ParallelFor(n, threads, [&](int i) {
    try {
      const std::string what = names.empty() ? "image " + std::to_string(i)
                                             : "frame " + Quoted(names[static_cast<size_t>(i)]);
      DescribeInto(describer, GreyOfImage(images[i], what), what, rows.row(i));
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
  return DescribeNamed(*d.frame, images, {}, threads);
}

cv::Mat1f DistanceMatrix(const cv::Mat& rows, int sequence_length, SequenceDirection direction,
                         const std::vector<int>& traversal_starts, int threads,
                         float* max_distance, std::optional<Metric> metric,
                         SequencePartial partial) {
  if (rows.empty() || (rows.type() != CV_8UC1 && rows.type() != CV_32FC1))
    throw InputError("descriptor rows of OpenCV type " + cv::typeToString(rows.type()) + " and " +
                     std::to_string(rows.rows) + " rows: expected at least one row of CV_8UC1 "
                     "(Hamming) or CV_32FC1 (L2)");
  if (sequence_length < 1)
    throw InputError("sequence_length = " + std::to_string(sequence_length) + ": expected >= 1");
  const Metric m = metric.value_or(MetricOfType(rows.type()));
  if ((m == Metric::kL2) != (rows.type() == CV_32FC1))
    throw InputError("descriptor rows of OpenCV type " + cv::typeToString(rows.type()) +
                     " with the " + EnumName(m) + " distance: expected CV_32FC1 rows for l2, "
                     "CV_8UC1 rows for hamming and l1");
  return NormalizedDistanceMatrix(rows, sequence_length, direction, traversal_starts, threads,
                                  max_distance, m, partial);
}

// ---- OnlineDetector ------------------------------------------------------------------------

struct OnlineDetector::State {
  OnlineOptions options;
  Describer describer;
  int width = 0, type = CV_8U;
  double unit = 0;  // binary: bits per row; float: largest single-frame distance so far
  std::unique_ptr<IncrementalIndex> map;  // the rows of every frame, searched (matching/)
  // Verification: the checker, every frame's features, the previous frame's candidates.
  std::unique_ptr<PairVerifier> verifier;
  std::vector<FrameFeatures> features;
  QueryVerification previous;
  // Sessions, tiling frames 0 .. Size() - 1; the frames' size ("WxH", "" unknown).
  std::vector<MapSession> sessions;
  std::string frame_size;
  // A loaded map: its path and the background check of its checksums (map_file.h).
  std::string map_path;
  std::shared_future<std::string> map_check;

  // The search of a frame whose row is in the map (AddDescriptor without the checks).
  OnlineResult Search(const cv::Mat& row);
  // `n` frames appended: they join the last session (one named "default" when none).
  void Appended(int n) {
    if (sessions.empty()) sessions.push_back({"default", NowUtc(), 0, 0});
    sessions.back().count += n;
  }
  int SessionOf(int frame) const {
    auto it = std::upper_bound(sessions.begin(), sessions.end(), frame,
                               [](int f, const MapSession& m) { return f < m.first; });
    return static_cast<int>(it - sessions.begin()) - 1;
  }
  // S(q, j) with the query's rows `queries` (row q, its session starting at row q_first) and
  // the map's frame j, neither sequence running across the start of its session.
  double Distance(const cv::Mat& queries, int q, int q_first, int j, double* largest) const {
    const MapSession& sj = sessions[static_cast<std::size_t>(SessionOf(j))];
    return SequenceCellDistance(queries.rowRange(q_first, q + 1), q - q_first,
                                map->Rows().rowRange(sj.first, j + 1), j - sj.first,
                                options.sequence_length, false, largest,
                                SequencePartial::kScale);
  }
  // The candidates kept of `scored` (distance, frame) and their scores, into r.candidates.
  void Choose(std::vector<std::pair<double, int>>& scored, double unit_now,
              OnlineResult& r) const;
  // A damaged loaded map (its background check failed): InputError. `wait`: wait for the
  // check; else only a check already finished counts.
  void ThrowIfDamaged(bool wait) const {
    if (!map_check.valid()) return;
    if (!wait && map_check.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
      return;
    const std::string& error = map_check.get();
    if (!error.empty()) throw InputError(error);
  }
  static std::string NowUtc() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return text;
  }
};

OnlineDetector::OnlineDetector(const OnlineOptions& options) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = options;
  s.describer = MakeDescriber(options);  // checks the options
  Require(s.describer.descriptor->Distance() != DistanceKind::kL1, "descriptor",
          options.descriptor.name,
          "a Hamming or L2 descriptor (" + s.describer.descriptor->Name() +
              "'s L1 distance has no index for the search beyond exact_limit: use "
              "DescribeImages and DistanceMatrix, or Test_OpenABLE)");
  s.width = s.describer.frame->RowWidth();
  s.type = s.describer.frame->RowType();
  if (s.type == CV_8U) s.unit = 8.0 * s.width;
  IncrementalIndexOptions index;
  index.exact_limit = options.exact_limit;
  index.block_frames = options.block_frames;
  index.background_merges = options.background_merges;
  index.approximate = options.approximate;
  s.map = std::make_unique<IncrementalIndex>(s.width, s.type, index);
  if (options.verification.enabled) {
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
int OnlineDetector::Size() const { return state_->map->Size(); }
int OnlineDetector::RowWidth() const { return state_->width; }
int OnlineDetector::RowType() const { return state_->type; }
cv::Mat OnlineDetector::Descriptors() const { return state_->map->Rows(); }
int OnlineDetector::Blocks() const { return state_->map->Blocks(); }
void OnlineDetector::FinishMerges() { state_->map->FinishMerges(); }
std::int64_t OnlineDetector::MemoryBytes() const { return state_->map->MemoryBytes(); }

OnlineResult OnlineDetector::AddFrame(const cv::Mat& image) {
  State& s = *state_;
  s.ThrowIfDamaged(false);
  const auto start = Clock::now();
  cv::Mat row(1, s.width, s.type);
  const std::string what = "frame " + std::to_string(Size());
  const cv::Mat1b grey = GreyOfImage(image, what);
  const std::string size = SizeText(grey.size());
  CheckFrameSize(what, size, s.frame_size);
  DescribeInto(*s.describer.frame, grey, what, row);
  s.frame_size = size;
  const double describe = Seconds(start);
  if (!s.verifier) {
    OnlineResult r = AddDescriptor(row);
    r.describe_seconds = describe;
    return r;
  }
  const auto verify_start = Clock::now();
  s.features.push_back(s.verifier->Extract(grey));
  double verify = Seconds(verify_start);
  OnlineResult r = s.Search(row);
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
    throw InputError("OnlineDetector::AddToMap: verification is on (OnlineOptions::"
                     "verification.enabled) and needs each frame's image: add the frames with "
                     "AddFrame");
  if (rows.empty()) return;
  if (rows.cols != s.width || rows.type() != s.type)
    throw InputError("map rows of " + std::to_string(rows.rows) + "x" + std::to_string(rows.cols) +
                     " " + cv::typeToString(rows.type()) + ": expected n x" +
                     std::to_string(s.width) + " " + cv::typeToString(s.type) + " (" +
                     s.describer.descriptor->Name() + ")");
  if (s.type == CV_32F && !cv::checkRange(rows))
    throw InputError("map rows hold a value that is not finite");
  s.ThrowIfDamaged(false);
  s.map->Reserve(s.map->Size() + rows.rows);
  for (int i = 0; i < rows.rows; ++i) s.map->Append(rows.row(i));
  s.Appended(rows.rows);
  s.map->Update(s.map->Size() - s.options.exclusion, /*background=*/false);
}

cv::Mat OnlineDetector::DescribeFrames(const std::vector<cv::Mat>& images,
                                       const std::vector<std::string>& names) const {
  const State& s = *state_;
  if (!names.empty() && names.size() != images.size())
    throw std::invalid_argument("OnlineDetector::DescribeFrames: " +
                                std::to_string(names.size()) + " names for " +
                                std::to_string(images.size()) + " images");
  std::string size = s.frame_size;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string mine = SizeText(images[i].size());
    CheckFrameSize(names.empty() ? "image " + std::to_string(i) : "frame " + Quoted(names[i]),
                   mine, size);
    size = mine;
  }
  return DescribeNamed(*s.describer.frame, images, names, 0);
}

void OnlineDetector::AddImagesToMap(const std::vector<cv::Mat>& images,
                                    const std::vector<std::string>& names) {
  State& s = *state_;
  AddToMap(DescribeFrames(images, names));
  if (!images.empty()) s.frame_size = SizeText(images.front().size());
}

OnlineResult OnlineDetector::AddDescriptor(const cv::Mat& row) {
  State& s = *state_;
  if (row.rows != 1 || row.cols != s.width || row.type() != s.type)
    throw InputError("descriptor row of " + std::to_string(row.rows) + "x" +
                     std::to_string(row.cols) + " " + cv::typeToString(row.type()) +
                     ": expected 1x" + std::to_string(s.width) + " " +
                     cv::typeToString(s.type) + " (" + s.describer.descriptor->Name() + ")");
  if (s.type == CV_32F && !cv::checkRange(row))
    throw InputError("descriptor row holds a value that is not finite");
  if (s.verifier)
    throw InputError("OnlineDetector::AddDescriptor: verification is on (OnlineOptions::"
                     "verification.enabled) and needs each frame's image: use AddFrame");
  s.ThrowIfDamaged(false);
  return s.Search(row);
}

OnlineResult OnlineDetector::State::Search(const cv::Mat& row) {
  State& s = *this;
  const auto start = Clock::now();
  s.map->Append(row);
  s.Appended(1);
  OnlineResult r;
  r.frame = s.map->Size() - 1;
  r.session = static_cast<int>(s.sessions.size()) - 1;
  const int q = r.frame;
  // Frames j <= q - exclusion of its own session, and every frame of the earlier ones.
  const int first = s.sessions.back().first;
  const int searchable = std::max(first, q - s.options.exclusion + 1);
  if (searchable > 0) {
    s.map->Update(searchable);
    // Each candidate frame is scored by its exact sequence sum (one traversal, forward). The
    // frames after the query are not known yet, so a candidate among the first L - 1 frames
    // (a sum with fewer than L terms) is scaled up to L terms (Sequence_partial scale): the
    // batch run's default, ahead, would read frames the detector has not seen.
    double* largest = s.type == CV_32F ? &s.unit : nullptr;
    std::vector<std::pair<double, int>> scored;
    for (const int j : s.map->Candidates(row, searchable, &r.approximate))
      scored.emplace_back(s.Distance(s.map->Rows(), q, first, j, largest), j);
    s.Choose(scored, s.unit, r);
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
    chosen = DistinctBest(cells, s.options.verification.candidates, s.options.score_window);
  } else {
    const size_t k = std::min(scored.size(), static_cast<size_t>(s.options.candidates));
    std::partial_sort(scored.begin(), scored.begin() + k, scored.end());
    for (size_t i = 0; i < k; ++i) chosen.push_back(i);
  }
  // The ratio's rivals: every candidate scored.
  std::vector<std::pair<float, int>> rivals;
  if (s.options.score == MatchScore::kRatio)
    for (const auto& [d, j] : scored) rivals.emplace_back(static_cast<float>(d), j);
  const double scale = s.options.sequence_length * unit_now;
  for (const size_t i : chosen) {
    LoopCandidate c;
    c.frame = scored[i].second;
    c.session = s.SessionOf(c.frame);
    c.session_frame = c.frame - s.sessions[static_cast<std::size_t>(c.session)].first;
    c.distance = scored[i].first;
    c.normalized = scale > 0 ? c.distance / scale : 0.0;
    c.score = s.options.score == MatchScore::kRatio
                  ? ScoreOfCandidate(rivals, i, MatchScore::kRatio, s.options.score_window)
                  : c.normalized;
    c.accepted = c.score <= s.options.threshold;
    r.candidates.push_back(c);
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
  for (const char c : time)
    if (static_cast<unsigned char>(c) <= 0x20 || c == 0x7f)
      throw InputError("OnlineDetector::StartSession: session time " + Quoted(time) +
                       ": expected a time without spaces, e.g. 2026-11-27T09:30:00Z");
  s.sessions.push_back({name, time.empty() ? State::NowUtc() : time, Size(), 0});
}

const std::vector<MapSession>& OnlineDetector::Sessions() const { return state_->sessions; }

int OnlineDetector::SessionOf(int frame) const {
  if (frame < 0 || frame >= Size())
    throw InputError("OnlineDetector::SessionOf(" + std::to_string(frame) + "): expected a frame "
                     "of the map, 0 to " + std::to_string(Size() - 1));
  return state_->SessionOf(frame);
}

const std::string& OnlineDetector::FrameSize() const { return state_->frame_size; }

void OnlineDetector::CheckMap() const { state_->ThrowIfDamaged(true); }

std::vector<OnlineResult> OnlineDetector::Query(const cv::Mat& rows,
                                                const std::vector<std::string>& sessions) const {
  const State& s = *state_;
  if (s.verifier)
    throw InputError("OnlineDetector::Query: verification is on (OnlineOptions::verification."
                     "enabled) and needs each query's image and features: add the frames with "
                     "AddFrame, or query with a detector without verification");
  if (rows.cols != s.width || rows.type() != s.type)
    throw InputError("query rows of " + std::to_string(rows.rows) + "x" +
                     std::to_string(rows.cols) + " " + cv::typeToString(rows.type()) +
                     ": expected n x" + std::to_string(s.width) + " " +
                     cv::typeToString(s.type) + " (" + s.describer.descriptor->Name() + ")");
  if (s.type == CV_32F && !rows.empty() && !cv::checkRange(rows))
    throw InputError("query rows hold a value that is not finite");
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
      throw InputError("session " + Quoted(name) + " is not in the map; its sessions: " +
                       (names.empty() ? "none" : names));
    }
    if (!allowed[i]) allowed_frames += s.sessions[i].count;
    allowed[i] = 1;
  }
  const bool exact_sessions =
      !sessions.empty() && (s.map->Blocks() == 0 || allowed_frames <= s.options.exact_limit);
  const cv::Mat queries = rows.isContinuous() ? rows : rows.clone();
  std::vector<OnlineResult> out(static_cast<std::size_t>(queries.rows));
  const int size = Size();
  ParallelFor(queries.rows, 0, [&](int i) {
    const auto start = Clock::now();
    OnlineResult& r = out[static_cast<std::size_t>(i)];
    r.frame = i;
    if (size == 0) return;
    std::vector<int> candidates;
    if (exact_sessions) {
      for (std::size_t k = 0; k < s.sessions.size(); ++k)
        if (allowed[k])
          for (int j = s.sessions[k].first; j < s.sessions[k].first + s.sessions[k].count; ++j)
            candidates.push_back(j);
    } else {
      candidates = s.map->Candidates(queries.row(i), size, &r.approximate);
    }
    double largest = s.unit;
    std::vector<std::pair<double, int>> scored;
    for (const int j : candidates)
      if (allowed[static_cast<std::size_t>(s.SessionOf(j))])
        scored.emplace_back(s.Distance(queries, i, 0, j, s.type == CV_32F ? &largest : nullptr),
                            j);
    s.Choose(scored, s.type == CV_32F ? largest : s.unit, r);
    r.search_seconds = Seconds(start);
  });
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

// The settings that make the rows: a map made with others cannot be searched with this
// detector's rows.
std::vector<std::pair<std::string, std::string>> DescriptionSettings(const OnlineOptions& o) {
  return {{"descriptor", o.descriptor.name},
          {"description", EnumName(o.description)},
          {"patch_size", std::to_string(o.descriptor.patch_size)},
          {"ldb_bits", std::to_string(o.descriptor.ldb_bits)},
          {"grid_x", std::to_string(o.grid_x)},
          {"grid_y", std::to_string(o.grid_y)}};
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

}  // namespace

void OnlineDetector::SaveMap(const std::string& path) {
  State& s = *state_;
  // A map loaded damaged is not written out again as if it were sound.
  s.ThrowIfDamaged(true);
  MapFile map;
  map.settings = {{"openable", kVersion},
                  {"frames", std::to_string(Size())},
                  {"row_width", std::to_string(s.width)},
                  {"row_type", s.type == CV_8U ? "CV_8U" : "CV_32F"},
                  {"unit", Exact(s.unit)},
                  {"frame_size", s.frame_size}};
  for (const auto& list : {DescriptionSettings(s.options), IndexSettings(s.options),
                           FeatureSettings(s.options)})
    map.settings.insert(map.settings.end(), list.begin(), list.end());
  map.sessions = s.sessions;
  map.blocks = s.map->SaveBlocks();
  map.rows = s.map->Rows();
  map.has_features = s.verifier != nullptr;
  if (map.has_features) map.features = s.features;
  WriteMapFile(path, map);
}

namespace {

// Checks that the map read from `path` can join a detector of `options` (description
// settings, rows, features), else one InputError naming the path and what differs. Returns
// the map's unit (float rows: the largest single-frame distance it had seen).
double CheckMapFits(const MapFile& map, const std::string& path, const OnlineOptions& options,
                    int width, int type, const std::string& descriptor,
                    const PairVerifier* verifier, double unit) {
  const std::string what = "the map was made with ";
  // Settings the map must share with this detector, else one line naming the first that differs.
  const auto require_same = [&](const std::vector<std::pair<std::string, std::string>>& settings,
                                const std::string& mine, const std::string& expected) {
    for (const auto& [key, value] : settings)
      if (map.Setting(key) != value)
        throw InputError(path + ": " + what + key + " = " + map.Setting(key) + "; this detector " +
                         mine + " " + key + " = " + value + " (" + expected + ")");
  };
  require_same(DescriptionSettings(options), "has",
               "expected the same description settings: descriptor, description, patch_size, "
               "ldb_bits, grid_x, grid_y");
  if (map.rows.cols != width || map.rows.depth() != type)
    throw InputError(path + ": the map's rows are " + std::to_string(map.rows.cols) + " " +
                     map.Setting("row_type") + "; expected " + std::to_string(width) + " " +
                     (type == CV_8U ? "CV_8U" : "CV_32F") + " (" + descriptor + ")");
  if (type == CV_32F && !map.rows.empty() && !cv::checkRange(map.rows))
    throw InputError(path + ": the map's rows hold a value that is not finite");
  if (verifier) {
    require_same(FeatureSettings(options), "verifies with",
                 "expected a map saved by a detector with the same verification features");
    if (!map.has_features || map.features.size() != static_cast<size_t>(map.rows.rows))
      throw InputError(path + ": the map holds no local features; expected a map saved by a "
                       "detector with verification enabled");
    // The matcher compares them with the descriptors of later frames.
    const int fwidth = verifier->DescriptorWidth(), ftype = verifier->DescriptorType();
    for (size_t i = 0; i < map.features.size(); ++i) {
      const cv::Mat& d = map.features[i].descriptors;
      if (!d.empty() && (d.cols != fwidth || d.type() != ftype))
        throw InputError(path + ": the local features of frame " + std::to_string(i) +
                         " have descriptors of " + std::to_string(d.cols) + " " +
                         cv::typeToString(d.type()) + "; expected " + std::to_string(fwidth) +
                         " " + cv::typeToString(ftype) + " (" + map.Setting("features") + ")");
    }
  }
  if (type == CV_32F) {
    const std::string text = map.Setting("unit");
    char* end = nullptr;
    unit = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || !std::isfinite(unit) || unit < 0)
      throw InputError(path + ": setting \"unit\" of the map is \"" + text +
                       "\": expected a number >= 0");
  }
  return unit;
}

}  // namespace

OnlineOptions MapOptions(const std::string& path, const OnlineOptions& base) {
  MapReadOptions read;
  read.header_only = true;
  const MapFile map = ReadMapFile(path, read);
  OnlineOptions o = base;
  const auto number = [&](const std::string& key, auto& field) {
    const std::string text = map.Setting(key);
    try {
      std::size_t used = 0;
      const long long v = std::stoll(text, &used);
      if (used == text.size()) {
        field = static_cast<std::decay_t<decltype(field)>>(v);
        return;
      }
    } catch (const std::exception&) {
    }
    throw InputError(path + ": setting \"" + key + "\" of the map is " + Quoted(text) +
                     ": expected a whole number");
  };
  o.descriptor.name = map.Setting("descriptor");
  o.description = ParseEnum<DescriptionType>(map.Setting("description"),
                                             path + ": setting \"description\"");
  number("patch_size", o.descriptor.patch_size);
  number("ldb_bits", o.descriptor.ldb_bits);
  number("grid_x", o.grid_x);
  number("grid_y", o.grid_y);
  number("exclusion", o.exclusion);
  number("exact_limit", o.exact_limit);
  number("block_frames", o.block_frames);
  o.approximate.engine = map.Setting("engine");
  number("hnsw_m", o.approximate.hnsw_m);
  number("hnsw_ef_construction", o.approximate.hnsw_ef_construction);
  number("ivf_lists", o.approximate.ivf_lists);
  number("lsh_tables", o.approximate.lsh_tables);
  number("lsh_key_bits", o.approximate.lsh_key_bits);
  number("lsh_probe_level", o.approximate.lsh_probe_level);
  number("kd_trees", o.approximate.kd_trees);
  number("seed", o.approximate.seed);
  try {
    o.Check();
  } catch (const InputError& e) {
    throw InputError(path + ": the map's settings are not valid options: " + e.what());
  }
  return o;
}

OnlineDetector::LoadedMap OnlineDetector::LoadMap(const std::string& path,
                                                  const MapReadOptions& read) {
  State& s = *state_;
  if (Size() != 0)
    throw InputError("OnlineDetector::LoadMap(\"" + path + "\"): the detector holds " +
                     std::to_string(Size()) + " frames; expected an empty detector (load the "
                     "map before adding frames)");
  MapFile map = ReadMapFile(path, read);
  const double unit = CheckMapFits(map, path, s.options, s.width, s.type,
                                   s.describer.descriptor->Name(), s.verifier.get(), s.unit);
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
  if (!out.rebuilt) {
    try {
      s.map->Restore(map.rows, map.blocks, map.mapping);
    } catch (const std::invalid_argument& e) {
      throw InputError(path + ": " + e.what());
    }
  } else {
    s.map->Restore(map.rows, {}, map.mapping);
    s.map->Update(searchable, /*background=*/false);
  }
  s.unit = unit;
  if (s.verifier) s.features = std::move(map.features);
  s.sessions = std::move(map.sessions);
  s.frame_size = map.Setting("frame_size");
  s.map_path = path;
  s.map_check = map.check;
  out.blocks = s.map->Blocks();
  return out;
}

void OnlineDetector::AppendMap(const std::string& path) {
  State& s = *state_;
  s.ThrowIfDamaged(true);
  // Its rows are copied into this map: checked before they are.
  MapFile map = ReadMapFile(path, {/*in_place=*/true, /*check_in_background=*/false});
  const double unit = CheckMapFits(map, path, s.options, s.width, s.type,
                                   s.describer.descriptor->Name(), s.verifier.get(), s.unit);
  const std::string size = map.Setting("frame_size");
  if (!size.empty() && !s.frame_size.empty() && size != s.frame_size)
    throw InputError(path + ": the map's frames are " + size + "; this map's are " +
                     s.frame_size + " (expected frames of one camera at one size)");
  for (const MapSession& m : map.sessions)
    for (const MapSession& mine : s.sessions)
      if (m.name == mine.name && mine.count > 0)
        throw InputError(path + ": both maps have a session named " + Quoted(m.name) +
                         "; expected maps of distinct sessions (each traversal once)");
  if (map.rows.rows == 0) return;
  const int first = Size();
  if (!s.sessions.empty() && s.sessions.back().count == 0) s.sessions.pop_back();
  s.map->Reserve(first + map.rows.rows);
  for (int i = 0; i < map.rows.rows; ++i) s.map->Append(map.rows.row(i));
  for (MapSession m : map.sessions) {
    m.first += first;
    s.sessions.push_back(std::move(m));
  }
  if (s.frame_size.empty()) s.frame_size = size;
  if (s.type == CV_32F) s.unit = std::max(s.unit, unit);
  if (s.verifier)
    for (FrameFeatures& f : map.features) s.features.push_back(std::move(f));
  s.map->Update(Size() - s.options.exclusion, /*background=*/false);
}

}  // namespace openable
