#include "matching/search/incremental_index.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "matching/search/approximate_engine.h"

namespace openable {

struct IncrementalIndex::State {
  IncrementalIndexOptions options;
  int width = 0, type = CV_8U;

  // Rows of every frame, in a buffer that doubles when full (amortised O(1) per row). A
  // restored map's rows may lie in a mapped file (rows_owner keeps it): the buffer is then
  // exactly full, so the first Append copies them into a buffer of our own.
  cv::Mat buffer;
  int size = 0;
  std::shared_ptr<const void> rows_owner;

  // Index blocks over rows [first, first + count), contiguous and in order from row 0; counts
  // are block_frames x 2^m, non-increasing along the vector.
  struct Block {
    int first = 0, count = 0;
    std::unique_ptr<ApproximateIndex> index;
  };
  std::vector<Block> blocks;
  int indexed = 0;  // rows covered by blocks

  // A merge of blocks[block] and blocks[block + 1] being built (one at a time).
  struct Merge {
    size_t block = 0;
    int first = 0, count = 0;
    std::future<std::unique_ptr<ApproximateIndex>> index;
  };
  std::optional<Merge> merge;
  std::future<void> disposal;  // freeing the indices a merge replaced

  // Builds an index over rows [first, first + count).
  std::unique_ptr<ApproximateIndex> Index(int first, int count) const {
    return std::make_unique<ApproximateIndex>(buffer.rowRange(first, first + count),
                                              options.approximate);
  }

  // Installs a finished merge (waiting for it when `wait`), then starts the next one.
  void FinishMerge(bool wait, bool background = true) {
    if (merge &&
        (wait || merge->index.wait_for(std::chrono::seconds(0)) == std::future_status::ready)) {
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
};

IncrementalIndex::IncrementalIndex(int width, int type, const IncrementalIndexOptions& options)
    : state_(std::make_unique<State>()) {
  state_->options = options;
  state_->width = width;
  state_->type = type;
}

IncrementalIndex::~IncrementalIndex() = default;

void IncrementalIndex::Reserve(int rows) {
  State& s = *state_;
  if (rows <= s.buffer.rows) return;
  cv::Mat bigger(rows, s.width, s.type);
  if (s.size > 0) s.buffer.rowRange(0, s.size).copyTo(bigger.rowRange(0, s.size));
  s.buffer = bigger;
  s.rows_owner.reset();
}

void IncrementalIndex::Append(const cv::Mat& row) {
  State& s = *state_;
  if (s.size == s.buffer.rows) Reserve(std::max(64, 2 * s.buffer.rows));
  row.copyTo(s.buffer.row(s.size));
  ++s.size;
}

void IncrementalIndex::Update(int searchable, bool background) {
  State& s = *state_;
  if (searchable <= s.options.exact_limit) return;
  if (!background) {
    s.FinishMerge(true, false);
    // Rows added at once (a map loaded, AddToMap): the blocks the binary counter of block
    // sizes ends with, each built once from its rows, rather than every block of block_frames
    // and every merge on the way, which indexed each row about log2(rows / block_frames)
    // times (docs/benchmarks.md, "Large maps"). A block is an index over its rows
    // alone, so the blocks are those the merges would have made. The blocks already built
    // that the final layout keeps (its leading ones) stay.
    const int unit = s.options.block_frames;
    const std::int64_t units = s.indexed / unit + (searchable - s.indexed) / unit;
    std::vector<std::pair<int, int>> layout;  // (first, count), sizes decreasing
    int first = 0;
    for (int bit = 30; bit >= 0; --bit)
      if ((units >> bit) & 1) {
        const int count = static_cast<int>((std::int64_t{1} << bit) * unit);
        layout.emplace_back(first, count);
        first += count;
      }
    std::size_t kept = 0;
    while (kept < s.blocks.size() && kept < layout.size() &&
           s.blocks[kept].first == layout[kept].first &&
           s.blocks[kept].count == layout[kept].second)
      ++kept;
    s.blocks.resize(kept);
    for (std::size_t b = kept; b < layout.size(); ++b)
      s.blocks.push_back(
          {layout[b].first, layout[b].second, s.Index(layout[b].first, layout[b].second)});
    s.indexed = first;
    return;
  }
  while (searchable - s.indexed >= s.options.block_frames) {
    s.blocks.push_back(
        {s.indexed, s.options.block_frames, s.Index(s.indexed, s.options.block_frames)});
    s.indexed += s.options.block_frames;
    if (!background) s.StartMerges(false);
  }
  s.FinishMerge(false, background);
}

std::vector<int> IncrementalIndex::Candidates(const cv::Mat& row, int searchable,
                                              bool* approximate) const {
  const State& s = *state_;
  std::vector<int> out;
  *approximate = !s.blocks.empty();
  if (s.blocks.empty()) {
    out.reserve(static_cast<size_t>(std::max(0, searchable)));
    for (int j = 0; j < searchable; ++j) out.push_back(j);
    return out;
  }
  for (const auto& b : s.blocks) {
    const CandidateLists found = b.index->Search(row);
    for (const Candidate& c : found[0]) out.push_back(b.first + c.reference);
  }
  for (int j = s.indexed; j < searchable; ++j) out.push_back(j);
  return out;
}

void IncrementalIndex::FinishMerges() {
  while (state_->merge) state_->FinishMerge(true);
}

std::vector<IncrementalIndex::SavedBlock> IncrementalIndex::SaveBlocks() {
  FinishMerges();
  std::vector<SavedBlock> out;
  for (const auto& b : state_->blocks) out.push_back({b.first, b.count, b.index->Serialize(), {}});
  return out;
}

void IncrementalIndex::Restore(const cv::Mat& rows, const std::vector<SavedBlock>& blocks,
                               std::shared_ptr<const void> rows_owner) {
  State& s = *state_;
  if (s.size != 0) throw std::invalid_argument("IncrementalIndex::Restore: the index is not empty");
  if (!rows.empty() && (rows.cols != s.width || rows.depth() != s.type))
    throw std::invalid_argument("IncrementalIndex::Restore: rows of another width or type");
  // The layout this index would have built: contiguous from row 0, sizes block_frames x 2^m,
  // strictly decreasing (two equal neighbours would have been merged).
  int next = 0;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const SavedBlock& b = blocks[i];
    int m = b.count / s.options.block_frames;
    const bool power = b.count > 0 && b.count % s.options.block_frames == 0 && (m & (m - 1)) == 0;
    if (b.first != next || !power || (i > 0 && b.count >= blocks[i - 1].count) ||
        b.count > rows.rows - next)
      throw std::invalid_argument("IncrementalIndex::Restore: block " + std::to_string(i) +
                                  " (rows " + std::to_string(b.first) + ", " +
                                  std::to_string(b.count) +
                                  " of them) does not follow "
                                  "the layout of blocks of " +
                                  std::to_string(s.options.block_frames) + " x 2^m rows");
    next += b.count;
  }
  if (rows.rows > 0 && rows_owner && rows.isContinuous()) {
    s.buffer = rows;  // a header: the rows stay where they lie
    s.rows_owner = std::move(rows_owner);
  } else if (rows.rows > 0) {
    s.buffer = cv::Mat(std::max(64, rows.rows), s.width, s.type);
    rows.copyTo(s.buffer.rowRange(0, rows.rows));
  }
  s.size = rows.rows;
  for (const SavedBlock& b : blocks)
    s.blocks.push_back(
        {b.first, b.count,
         std::make_unique<ApproximateIndex>(s.buffer.rowRange(b.first, b.first + b.count),
                                            s.options.approximate, b.Bytes())});
  s.indexed = next;
}

cv::Mat IncrementalIndex::Rows() const {
  const State& s = *state_;
  // No row yet (no buffer): 0 rows of the index's width, which a saved map records as it is.
  if (s.size == 0) return cv::Mat(0, s.width, s.type);
  return s.buffer.rowRange(0, s.size);
}
int IncrementalIndex::Size() const { return state_->size; }
int IncrementalIndex::Blocks() const { return static_cast<int>(state_->blocks.size()); }

std::int64_t IncrementalIndex::MemoryBytes() const {
  const State& s = *state_;
  std::int64_t bytes = static_cast<std::int64_t>(s.buffer.total()) * s.buffer.elemSize();
  // Each index holds a copy of its rows (for the exact distances) plus its engine's structure
  // (ApproximateEngineEntry::bytes_per_row).
  const std::int64_t row_bytes = s.width * static_cast<std::int64_t>(s.buffer.elemSize());
  const ApproximateEngineEntry& engine =
      FindApproximateEngine(s.options.approximate.engine, s.type);
  const std::int64_t per_row = (engine.owns_rows ? 0 : row_bytes) +
                               engine.bytes_per_row(s.options.approximate, s.type, row_bytes);
  auto index_bytes = [&](std::int64_t rows) { return rows * per_row; };
  for (const auto& b : s.blocks) bytes += index_bytes(b.count);
  // A merge being built: its index and the copy of its rows handed to the build.
  if (s.merge) bytes += index_bytes(s.merge->count) + s.merge->count * row_bytes;
  return bytes;
}

}  // namespace openable
