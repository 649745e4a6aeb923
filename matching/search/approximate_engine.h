// What an approximate-search engine provides to ApproximateIndex (matching/search/approximate.h):
// an entry of the table of matching/search/engine_registry.cc (name, help, whether it needs FAISS,
// its build and its memory per row) and the index it builds (EngineIndex). The helpers below are
// shared by the engines and by the exact search of approximate.cc.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "OpenABLE/base/threading.h"
#include "matching/search/approximate.h"

namespace openable {

// One built index of an engine, over the references handed to its build.
class EngineIndex {
 public:
  virtual ~EngineIndex() = default;
  // Up to options.k candidates for every row of `queries` (at least one row, continuous, the
  // references' type and width, all checked by ApproximateIndex) with exact distances
  // (RowDistance, matching/distances.h), sorted as CandidateLists says. `options` are the
  // index's (its k, threads and search budget as SetSearchBudget last set them). Reads the
  // index only: may be called from several threads at once.
  virtual CandidateLists Search(const cv::Mat& queries,
                                const ApproximateOptions& options) const = 0;
  // Takes the search budget of `options` (checked; the build's other fields) for later
  // searches. Not while a Search runs. An engine that reads its budget from the options of
  // each Search has nothing to do.
  virtual void SetSearchBudget(const ApproximateOptions& options) { (void)options; }
  // The index's structure, read back by the engine's build from `saved`; empty when the engine
  // builds its index again from the rows instead.
  virtual std::vector<std::uint8_t> Serialize() const { return {}; }
};

// An engine of the table (matching/search/engine_registry.cc).
struct ApproximateEngineEntry {
  // Its name: a value of ApproximateOptions::engine and of the key Approximate_engine (lower
  // case, no spaces).
  const char* name;
  // What it is, for the help of Approximate_engine after "<name>, " (no final full stop).
  const char* summary;
  // Built in the run-time module libopenable_faiss.so: a build without FAISS refuses it
  // (CheckEngineAvailable).
  bool needs_faiss;
  // Indexes binary (CV_8U) rows only: ApproximateIndex refuses float rows for it.
  bool binary_only;
  // Its index keeps what it needs of the references (a copy of its own), so that
  // ApproximateIndex frees the copy it handed to the build once the index is built.
  bool owns_rows;
  // Builds the index over `references` (continuous CV_8UC1 or CV_32FC1 rows, at least one,
  // finite; held by ApproximateIndex as long as the index lives, so the index may keep a
  // header of them) with `options` (checked, engine resolved to this one). `saved` is empty,
  // or the bytes of Serialize() of an index built over the same references with the same
  // options: the index is then read from them when the engine can (std::invalid_argument when
  // they hold another index), in place when saved.owner is set and its form allows.
  // Deterministic for given references and options.
  std::unique_ptr<EngineIndex> (*build)(const cv::Mat& references,
                                        const ApproximateOptions& options, const SavedIndex& saved);
  // Bytes the index holds per reference row besides ApproximateIndex's own copy of the rows
  // (an estimate, for IncrementalIndex::MemoryBytes); `row_bytes` is one row's size.
  std::int64_t (*bytes_per_row)(const ApproximateOptions& options, int depth,
                                std::int64_t row_bytes);
};

// The order of CandidateLists: increasing distance, ties by increasing reference row.
inline bool CandidateBefore(const Candidate& a, const Candidate& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.reference < b.reference);
}

inline void SortCandidates(std::vector<Candidate>& c) {
  std::sort(c.begin(), c.end(), CandidateBefore);
}

// Queries handed to one thread at a time.
inline constexpr int kQueryBlock = 32;

// Runs body(first, last) over [0, count) in blocks of `block` items on `threads` threads
// (0: all cores). The first exception thrown by a block is rethrown on the calling thread once
// all have stopped.
template <typename Body>
void ParallelBlocks(int count, int block, int threads, Body body) {
  const int blocks = (count + block - 1) / block;
  ParallelFor(blocks, threads, [&](int b) { body(b * block, std::min(count, (b + 1) * block)); });
}

}  // namespace openable
