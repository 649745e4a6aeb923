#include "OpenABLE/online/online.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <optional>
#include <mutex>
#include <thread>
#include <utility>

#include <opencv2/core/utility.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/image/preprocess.h"
#include "descriptors/registry.h"
#include "matching/distances.h"
#include "matching/normalize.h"

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

// The grey 8-bit image the descriptors see, from the image types AddFrame takes: 8-bit images
// are first scaled to [0, 1] floats, as frame sources give them, so that the grey conversion
// (ToGray8) is the one Test_OpenABLE applies and rows equal the batch rows bit for bit.
cv::Mat1b GreyOf(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw InputError(what + " is empty (expected an image)");
  const int depth = image.depth(), channels = image.channels();
  if ((depth != CV_8U && depth != CV_32F) || (channels != 1 && channels != 3))
    throw InputError(what + " has OpenCV type " + cv::typeToString(image.type()) +
                     " (expected CV_8UC1, CV_8UC3 (BGR), CV_32FC1 or CV_32FC3 in [0, 1])");
  if (depth == CV_32F) return ToGray8(image);
  cv::Mat scaled;
  image.convertTo(scaled, CV_32F, 1.0 / 255.0);
  return ToGray8(scaled);
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
  Require(exact_limit >= 0, "exact_limit", std::to_string(exact_limit), ">= 0");
  Require(block_frames >= 16, "block_frames", std::to_string(block_frames), ">= 16");
  try {
    approximate.Check();
  } catch (const std::exception& e) {
    throw InputError("OnlineOptions.approximate: " + std::string(e.what()));
  }
  Require(approximate.k >= candidates, "approximate.k", std::to_string(approximate.k),
          ">= candidates (" + std::to_string(candidates) + ")");
}

Describer MakeDescriber(const OnlineOptions& options) {
  options.Check();
  DescriptorOptions d;
  d.patch_size = options.patch_size;
  d.ldb_bits = options.ldb_bits;
  Describer out;
  out.descriptor = CreateDescriptor(options.descriptor, d);
  // A grey image per frame: descriptors of several channels (D-LDB: grey + disparity) need
  // stereo pairs.
  Require(out.descriptor->Channels() == 1, "descriptor", options.descriptor,
          "a single-camera descriptor (" + out.descriptor->Name() +
              " needs stereo pairs: use Test_OpenABLE with Camera_type 1)");
  out.frame = std::make_unique<FrameDescriber>(*out.descriptor, options.description,
                                               options.grid_x, options.grid_y, 1);
  return out;
}

namespace {

// Describes one image with `describer`, checking its size.
void DescribeInto(const FrameDescriber& describer, const cv::Mat& image, const std::string& what,
                  cv::Mat row) {
  const cv::Mat1b grey = GreyOf(image, what);
  const cv::Size need = describer.MinimumFrame();
  if (grey.cols < need.width || grey.rows < need.height)
    throw InputError(what + " is " + SizeText(grey.size()) + "; the grid needs at least " +
                     SizeText(need) + " pixels (grid_x by grid_y)");
  describer.Describe(grey, row);
}

}  // namespace

cv::Mat DescribeImages(const std::vector<cv::Mat>& images, const OnlineOptions& options,
                       int threads) {
  const Describer d = MakeDescriber(options);
  const int n = static_cast<int>(images.size());
  cv::Mat rows(n, d.frame->RowWidth(), d.frame->RowType());
  if (n == 0) return rows;
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min(threads, n);
  std::atomic<int> next{0};
  std::mutex mutex;
  int error_index = n;
  std::string error;
  auto work = [&]() {
    for (int i; (i = next++) < n;) {
      try {
        DescribeInto(*d.frame, images[i], "image " + std::to_string(i), rows.row(i));
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex);
        if (i < error_index) error_index = i, error = e.what();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error_index < n) throw InputError(error);
  return rows;
}

cv::Mat1f DistanceMatrix(const cv::Mat& rows, int sequence_length, SequenceDirection direction,
                         const std::vector<int>& traversal_starts, int threads,
                         float* max_distance) {
  if (rows.empty() || (rows.type() != CV_8UC1 && rows.type() != CV_32FC1))
    throw InputError("descriptor rows of OpenCV type " + cv::typeToString(rows.type()) + " and " +
                     std::to_string(rows.rows) + " rows: expected at least one row of CV_8UC1 "
                     "(Hamming) or CV_32FC1 (L2)");
  if (sequence_length < 1)
    throw InputError("sequence_length = " + std::to_string(sequence_length) + ": expected >= 1");
  cv::Mat1f d = rows.type() == CV_8UC1 ? HammingDistances(rows, cv::Mat(), threads)
                                       : L2Distances(rows, cv::Mat(), threads);
  if (sequence_length > 1 || direction != SequenceDirection::kForward)
    SequenceDistancesInPlace(d, sequence_length, traversal_starts, traversal_starts, direction,
                             threads);
  const float m = NormalizeByMax(d);
  if (max_distance != nullptr) *max_distance = m;
  return d;
}

// ---- OnlineDetector ------------------------------------------------------------------------

struct OnlineDetector::State {
  OnlineOptions options;
  Describer describer;
  int width = 0, type = CV_8U;
  double unit = 0;  // binary: bits per row; float: largest single-frame distance so far

  // Rows of every frame, in a buffer that doubles when full (amortised O(1) per frame).
  cv::Mat buffer;
  int size = 0;

  // FLANN blocks over frames [first, first + count), contiguous and in order from frame 0;
  // counts are block_frames x 2^m, non-increasing along the vector.
  struct Block {
    int first = 0, count = 0;
    std::unique_ptr<ApproximateIndex> index;
  };
  std::vector<Block> blocks;
  int indexed = 0;  // frames covered by blocks

  cv::Mat Rows() const { return buffer.rowRange(0, size); }

  void Append(const cv::Mat& row) {
    if (size == buffer.rows) {
      cv::Mat bigger(std::max(64, 2 * buffer.rows), width, type);
      if (size > 0) buffer.rowRange(0, size).copyTo(bigger.rowRange(0, size));
      buffer = bigger;
    }
    row.copyTo(buffer.row(size));
    ++size;
  }

  // S(q, j): the sequence sum of matching/sequence.h (one traversal, forward), in double.
  double SequenceDistance(int q, int j) {
    const cv::Mat rows = Rows();
    const int terms = std::min({options.sequence_length, q + 1, j + 1});
    double s = 0;
    for (int k = 0; k < terms; ++k) {
      const double d = ExactRowDistance(rows, q - k, rows, j - k);
      if (type == CV_32F) unit = std::max(unit, d);
      s += d;
    }
    // As matching/sequence.cc rounds it: w L / c, then to float.
    if (terms < options.sequence_length) s = s * options.sequence_length / terms;
    return static_cast<float>(s);
  }

  // A merge of blocks[block] and blocks[block + 1] being built (one at a time).
  struct Merge {
    size_t block = 0;
    int first = 0, count = 0;
    std::future<std::unique_ptr<ApproximateIndex>> index;
  };
  std::optional<Merge> merge;
  std::future<void> disposal;  // freeing the indices a merge replaced

  // Builds an index over frames [first, first + count).
  std::unique_ptr<ApproximateIndex> Index(int first, int count) const {
    return std::make_unique<ApproximateIndex>(buffer.rowRange(first, first + count),
                                              options.approximate);
  }

  // Installs a finished merge (waiting for it when `wait`), then starts the next one.
  void FinishMerge(bool wait, bool background = true) {
    if (merge && (wait || merge->index.wait_for(std::chrono::seconds(0)) ==
                              std::future_status::ready)) {
      Block merged{merge->first, merge->count, merge->index.get()};
      // The two old indices are freed on another thread: freeing the tables of a large LSH
      // index takes a good part of a second.
      std::vector<std::unique_ptr<ApproximateIndex>> old;
      old.push_back(std::move(blocks[merge->block].index));
      old.push_back(std::move(blocks[merge->block + 1].index));
      if (disposal.valid()) disposal.wait();
      disposal = std::async(std::launch::async, [old = std::move(old)]() mutable { old.clear(); });
      blocks[merge->block] = std::move(merged);
      blocks.erase(blocks.begin() + static_cast<std::ptrdiff_t>(merge->block) + 1);
      merge.reset();
    }
    StartMerges(background);
  }

  // Merges neighbouring blocks of equal size (a binary counter of block sizes): on a
  // background thread, one at a time; or here, all of them, without background_merges.
  void StartMerges(bool background) {
    while (!merge) {
      size_t i = blocks.size();
      for (size_t b = blocks.size(); b-- > 1;)
        if (blocks[b - 1].count == blocks[b].count) {
          i = b - 1;
          break;
        }
      if (i == blocks.size()) return;
      const int first = blocks[i].first, count = 2 * blocks[i].count;
      if (!options.background_merges || !background) {
        blocks[i] = Block{first, count, Index(first, count)};
        blocks.erase(blocks.begin() + static_cast<std::ptrdiff_t>(i) + 1);
        continue;
      }
      // The rows are copied: the buffer may grow (and move) while the index is built.
      cv::Mat rows = buffer.rowRange(first, first + count).clone();
      const ApproximateOptions approximate = options.approximate;
      merge = Merge{i, first, count, std::async(std::launch::async, [rows, approximate]() {
                      return std::make_unique<ApproximateIndex>(rows, approximate);
                    })};
    }
  }

  // Indexes full blocks of the searchable frames [0, searchable) once the map is past
  // exact_limit.
  // `background` false: every merge is built here (a map loaded by AddToMap).
  void UpdateBlocks(int searchable, bool background = true) {
    if (searchable <= options.exact_limit) return;
    if (!background) FinishMerge(true, false);
    while (searchable - indexed >= options.block_frames) {
      blocks.push_back({indexed, options.block_frames, Index(indexed, options.block_frames)});
      indexed += options.block_frames;
      if (!background) StartMerges(false);
    }
    FinishMerge(false, background);
  }
};

OnlineDetector::OnlineDetector(const OnlineOptions& options) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.options = options;
  s.describer = MakeDescriber(options);  // checks the options
  s.width = s.describer.frame->RowWidth();
  s.type = s.describer.frame->RowType();
  if (s.type == CV_8U) s.unit = 8.0 * s.width;
}

OnlineDetector::~OnlineDetector() = default;

const OnlineOptions& OnlineDetector::Options() const { return state_->options; }
int OnlineDetector::Size() const { return state_->size; }
int OnlineDetector::RowWidth() const { return state_->width; }
int OnlineDetector::RowType() const { return state_->type; }
cv::Mat OnlineDetector::Descriptors() const { return state_->Rows(); }
int OnlineDetector::Blocks() const { return static_cast<int>(state_->blocks.size()); }
void OnlineDetector::FinishMerges() {
  while (state_->merge) state_->FinishMerge(true);
}

std::int64_t OnlineDetector::MemoryBytes() const {
  const State& s = *state_;
  std::int64_t bytes = static_cast<std::int64_t>(s.buffer.total()) * s.buffer.elemSize();
  // Each index holds a copy of its rows plus its tables; counted as twice the rows (LSH: 12
  // tables of one 4-byte id per row is less; k-d trees: 4 trees of nodes per row).
  for (const auto& b : s.blocks)
    bytes += 2 * static_cast<std::int64_t>(b.count) * s.width * s.buffer.elemSize();
  if (s.merge) bytes += 3 * static_cast<std::int64_t>(s.merge->count) * s.width * s.buffer.elemSize();
  return bytes;
}

OnlineResult OnlineDetector::AddFrame(const cv::Mat& image) {
  const auto start = Clock::now();
  cv::Mat row(1, state_->width, state_->type);
  DescribeInto(*state_->describer.frame, image, "frame " + std::to_string(state_->size), row);
  const double describe = Seconds(start);
  OnlineResult r = AddDescriptor(row);
  r.describe_seconds = describe;
  return r;
}

void OnlineDetector::AddToMap(const cv::Mat& rows) {
  State& s = *state_;
  if (rows.empty()) return;
  if (rows.cols != s.width || rows.type() != s.type)
    throw InputError("map rows of " + std::to_string(rows.rows) + "x" + std::to_string(rows.cols) +
                     " " + cv::typeToString(rows.type()) + ": expected n x" +
                     std::to_string(s.width) + " " + cv::typeToString(s.type) + " (" +
                     s.describer.descriptor->Name() + ")");
  if (s.type == CV_32F && !cv::checkRange(rows))
    throw InputError("map rows hold a value that is not finite");
  for (int i = 0; i < rows.rows; ++i) s.Append(rows.row(i));
  s.UpdateBlocks(s.size - s.options.exclusion, false);
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
  const auto start = Clock::now();
  s.Append(row);
  OnlineResult r;
  r.frame = s.size - 1;
  const int q = r.frame;
  const int searchable = q - s.options.exclusion + 1;  // frames j <= q - exclusion
  if (searchable > 0) {
    s.UpdateBlocks(searchable);
    // Candidate frames: every searchable frame while exact; else the FLANN candidates of each
    // block plus the unindexed searchable frames. Each is scored by its exact sequence sum.
    std::vector<std::pair<double, int>> scored;
    if (s.blocks.empty()) {
      scored.reserve(searchable);
      for (int j = 0; j < searchable; ++j) scored.emplace_back(s.SequenceDistance(q, j), j);
    } else {
      r.approximate = true;
      for (const auto& b : s.blocks) {
        const CandidateLists found = b.index->Search(row);
        for (const Candidate& c : found[0])
          scored.emplace_back(s.SequenceDistance(q, b.first + c.reference), b.first + c.reference);
      }
      for (int j = s.indexed; j < searchable; ++j)
        scored.emplace_back(s.SequenceDistance(q, j), j);
    }
    const size_t k = std::min(scored.size(), static_cast<size_t>(s.options.candidates));
    std::partial_sort(scored.begin(), scored.begin() + k, scored.end());
    const double scale = s.options.sequence_length * s.unit;
    for (size_t i = 0; i < k; ++i) {
      LoopCandidate c;
      c.frame = scored[i].second;
      c.distance = scored[i].first;
      c.normalized = scale > 0 ? c.distance / scale : 0.0;
      c.accepted = c.normalized <= s.options.threshold;
      r.candidates.push_back(c);
    }
  }
  r.search_seconds = Seconds(start);
  return r;
}

}  // namespace openable
