// A growing set of descriptor rows searched for the candidates of each new row: the map of the
// online loop detector (OpenABLE/online/online.h). Up to exact_limit searchable rows every one
// is scanned exactly; beyond, rows are indexed by options.approximate's engine in blocks of
// block_frames rows merged like a binary counter (sizes block_frames x 2^m, at most one of
// each), and only the newest unindexed rows are scanned exactly. Merges are built on a
// background thread while the old blocks go on being searched, so no row waits for a build.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "matching/search/approximate.h"

namespace openable {

struct IncrementalIndexOptions {
  int exact_limit = 20000;         // searchable rows scanned exactly before index blocks, >= 0
  int block_frames = 4096;         // rows of the smallest index block, >= 16
  bool background_merges = true;   // build merges on a background thread (see above)
  ApproximateOptions approximate;  // its k is the candidate count of each block
};

class IncrementalIndex {
 public:
  // Rows of `width` elements of `type` (CV_8U or CV_32F).
  IncrementalIndex(int width, int type, const IncrementalIndexOptions& options);
  ~IncrementalIndex();
  IncrementalIndex(const IncrementalIndex&) = delete;
  IncrementalIndex& operator=(const IncrementalIndex&) = delete;

  // Appends one row (1 x width, type) as row Size(); the buffer doubles when full.
  void Append(const cv::Mat& row);
  // Room for `rows` rows in all without growing (rows added at once: the doubling would leave
  // up to half the buffer unused).
  void Reserve(int rows);
  // Indexes full blocks of the rows [0, searchable) once `searchable` exceeds exact_limit.
  // `background` false builds every merge here (a map loaded all at once).
  void Update(int searchable, bool background = true);
  // The candidate rows for `row` among [0, searchable) (after Update(searchable)): every row
  // while exact; else the approximate candidates of each block plus the unindexed rows.
  // `approximate` receives whether the blocks were used.
  std::vector<int> Candidates(const cv::Mat& row, int searchable, bool* approximate) const;
  // Waits for a background merge to finish and installs its index.
  void FinishMerges();

  // One index block as a saved map holds it: rows [first, first + count) and the index's
  // ApproximateIndex::Serialize() (empty for FLANN, rebuilt on Restore).
  struct SavedBlock {
    int first = 0, count = 0;
    std::vector<std::uint8_t> index;
    // Instead of `index` (when that is empty): the same bytes where a mapped map file holds
    // them, read in place by an engine that can (SavedIndex).
    SavedIndex in_place;
    SavedIndex Bytes() const { return index.empty() ? in_place : SavedIndex(index); }
  };
  // The blocks in use, after waiting for a background merge (FinishMerges).
  std::vector<SavedBlock> SaveBlocks();
  // Appends `rows` to an empty index and installs `blocks` as its index blocks without
  // building them (FAISS indexes are read; FLANN's are built). The blocks must tile rows
  // [0, indexed) in order with sizes block_frames x 2^m, non-increasing, at most one of each,
  // as this index builds them; otherwise std::invalid_argument. Empty `blocks` leaves the
  // rows unindexed (Update indexes them). With `rows_owner` set, `rows` (continuous) are used
  // where they lie, kept alive and unchanged by it (a memory-mapped map file), until the first
  // Append copies them into a buffer of the index's own.
  void Restore(const cv::Mat& rows, const std::vector<SavedBlock>& blocks,
               std::shared_ptr<const void> rows_owner = {});

  cv::Mat Rows() const;              // Size() x width, a view of the stored rows
  int Size() const;                  // rows appended
  int Blocks() const;                // index blocks in use (0 while exact)
  std::int64_t MemoryBytes() const;  // rows + indices held now (estimate, see the .cc)

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace openable
