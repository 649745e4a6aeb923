// Approximate candidate search for very large reference sets: the k nearest references of each
// query found by an engine of matching/search/engine_registry.h (FAISS's HNSW and inverted
// files, OpenCV's FLANN), and the exact search they are measured against. FAISS lives in the
// module libopenable_faiss.so, loaded when the first FAISS index is built; a build without FAISS
// refuses its engines (CheckEngineAvailable). Every distance returned is exact, recomputed by
// RowDistance (matching/distances.h) after the search, so exact and approximate results give
// equal distances for equal pairs and recall can compare them with ==.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "matching/search/engine_registry.h"

namespace openable {

// One candidate reference of a query.
struct Candidate {
  int reference = -1;  // row of the reference set
  float distance = 0;  // Hamming bit count (CV_8U rows) or Euclidean distance (CV_32F rows)
};

// Candidates of each query, sorted by increasing distance, ties by increasing reference row.
using CandidateLists = std::vector<std::vector<Candidate>>;

// The bytes of a saved index (ApproximateIndex::Serialize) handed to a build. `owner`, when
// set, keeps them alive and unchanged as long as it is held (a memory-mapped map file): an
// engine whose saved form can be searched as it is (binary_ivf) then keeps `owner` and reads
// the bytes in place instead of copying them. Without it the bytes are read during the build
// only.
struct SavedIndex {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::shared_ptr<const void> owner;
  SavedIndex() = default;
  SavedIndex(const std::vector<std::uint8_t>& bytes) : data(bytes.data()), size(bytes.size()) {}
  SavedIndex(const std::uint8_t* bytes, std::size_t n, std::shared_ptr<const void> keep)
      : data(bytes), size(n), owner(std::move(keep)) {}
  bool empty() const { return size == 0; }
};

// The valid values of an integer field of ApproximateOptions, inclusive.
struct ApproximateRange {
  int min;
  int max;
};

// The settings of approximate search, the one struct of them: the keys Approximate_engine,
// Approximate_checks, Approximate_ef_search and Approximate_nprobe are bound onto its fields
// (ScaleOptions::approximate, config/config.cc), the online detector and its Python
// properties hold one, and the FAISS module's settings are made from it. Each field's range
// (k...Range) is written only here: Check() refuses values outside it, and the option table
// gives its keys the same bounds.
//
// Defaults, chosen with bench/bench_approximate.cc on Nordland winter queries against 50,000
// summer and distractor references: LSH 12 tables of 20-bit keys probed at level 2 (FLANN's
// usual setting for binary descriptors), and 4 k-d trees with 512 checks, where HOG gains most
// of the speed for little loss of place recall (docs/benchmarks.md, "Approximate search
// (FLANN): recall and speed").
struct ApproximateOptions {
  // The engine: a name of ApproximateEngineNames() (any case); auto, the default, the engine
  // the table chooses for the rows' kind (ResolvedEngine).
  std::string engine = kAutoApproximateEngine;
  // Candidates per query; more than the references gives them all.
  int k = 10;
  static constexpr ApproximateRange kKRange{1, std::numeric_limits<int>::max()};
  // k-d trees: references examined per query (best bin first); more = better recall, slower.
  // LSH ignores it (it reads every probed bucket).
  int checks = 512;
  static constexpr ApproximateRange kChecksRange{1, 100000};
  // LSH: hash tables; more = better recall, slower.
  int lsh_tables = 12;
  static constexpr ApproximateRange kLshTablesRange{1, 64};
  // LSH: bits of a table's key (capped at the descriptor's bits); fewer = larger buckets,
  // better recall, slower. Keys index a 2^bits bitset per table (FLANN's hash level): 24 bits
  // is 2 MB a table.
  int lsh_key_bits = 20;
  static constexpr ApproximateRange kLshKeyBitsRange{1, 24};
  // LSH multi-probe: also read the buckets of keys within this many flipped bits. Level l
  // probes sum_{i<=l} C(bits, i) keys per table: 211 at level 2 with 20-bit keys, 1351 at 3.
  int lsh_probe_level = 2;
  static constexpr ApproximateRange kLshProbeLevelRange{0, 3};
  // Randomised k-d trees.
  int kd_trees = 4;
  static constexpr ApproximateRange kKdTreesRange{1, 64};
  // HNSW: neighbours per node and layer (M of the paper; 2 M on the bottom layer).
  int hnsw_m = 32;
  static constexpr ApproximateRange kHnswMRange{4, 128};
  // HNSW: candidate list while inserting (efConstruction); more = better graph, slower build.
  int hnsw_ef_construction = 64;
  static constexpr ApproximateRange kHnswEfConstructionRange{8, 4096};
  // HNSW: candidate list while searching (efSearch), raised to k when smaller; more = better
  // recall, slower.
  int ef_search = 128;
  static constexpr ApproximateRange kEfSearchRange{1, 100000};
  // IVF: k-means cells; 0 = automatic, 2 sqrt(Nr) capped at Nr / 39 (FAISS's minimum of 39
  // training rows a cell), at least 1; otherwise capped at Nr.
  int ivf_lists = 0;
  static constexpr ApproximateRange kIvfListsRange{0, std::numeric_limits<int>::max()};
  // IVF: cells scanned per query (nprobe), capped at the cells; more = better recall, slower.
  int nprobe = 64;
  static constexpr ApproximateRange kNprobeRange{1, 65536};
  // Queries spread over this many threads (0 = all cores).
  int threads = 0;
  static constexpr ApproximateRange kThreadsRange{0, 4096};
  // Seed of the index build: cv::RNG of FLANN ("FLAN"); FAISS's IVF k-means takes its low 31
  // bits (HNSW levels are drawn from FAISS's fixed seed, and its rows are added on one thread,
  // which makes the graph deterministic).
  std::uint64_t seed = 0x464C414EULL;

  // Throws std::invalid_argument naming the field, the value and the valid range (or names).
  void Check() const;
};

// An index over a fixed set of references (rows of one CV_8UC1 or CV_32FC1 matrix).
class ApproximateIndex {
 public:
  // Copies `references` (Nr x W, Nr >= 1) and builds the index of options.engine (auto
  // resolved by the rows' type, ResolvedEngine) over them: binary rows for CV_8U, float rows
  // for CV_32F. Deterministic for given references and options (each engine's header says
  // how). Throws std::invalid_argument (a std::logic_error) on bad options, an empty set,
  // another type, or non-finite floats; InputError when an engine that needs FAISS is asked
  // of a build without FAISS.
  ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options);
  // The index of `references` from `saved`, bytes of Serialize() of an index built over the
  // same references with the same options: an engine that serialises its structure (FAISS's)
  // reads it rather than building it again (a million-row HNSW graph takes minutes to build, a
  // second to read); one whose Serialize() is empty (FLANN) builds it (deterministic, so the
  // same index). Throws std::invalid_argument when the bytes hold another kind of index or
  // another row count.
  // With `saved.owner` set and an engine that reads its saved form in place, `references` are
  // not copied either (the index keeps no rows of its own then).
  ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options,
                   const SavedIndex& saved);
  ~ApproximateIndex();
  ApproximateIndex(ApproximateIndex&&) noexcept;
  ApproximateIndex& operator=(ApproximateIndex&&) noexcept;
  ApproximateIndex(const ApproximateIndex&) = delete;
  ApproximateIndex& operator=(const ApproximateIndex&) = delete;

  // Up to options.k candidates for every row of `queries` (Nq x W, the references' type and
  // width; Nq may be 0), exact distances, sorted as CandidateLists says. LSH may return fewer
  // than k when few references share a probed bucket with the query (none at all is possible),
  // IVF when the probed cells hold fewer than k rows; k-d trees and HNSW return min(k, Nr).
  // Options().engine is the engine resolved (never auto).
  // Reads the index only: may be called from several threads at once. Throws
  // std::invalid_argument on queries of another type or width.
  CandidateLists Search(const cv::Mat& queries) const;

  int Size() const;   // Nr
  int Width() const;  // W
  int Type() const;   // CV_8U or CV_32F
  const ApproximateOptions& Options() const;
  // Takes the search budget of `options` (checks, ef_search, nprobe; the others must be
  // those of the build) for later searches, to tune it without rebuilding the index. Not
  // while a Search runs. Throws std::invalid_argument on bad options.
  void SetSearchBudget(const ApproximateOptions& options);
  // The index's structure for the constructor above: FAISS's serialisation of the index
  // (write_index / write_index_binary, including FAISS's own copy of the rows); empty for an
  // engine that rebuilds it from the rows (FLANN's LSH tables and k-d trees: milliseconds to
  // seconds).
  std::vector<std::uint8_t> Serialize() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The exact k nearest references of every query by brute force (Hamming: the popcount kernel
// of distances.h; L2: one matrix product per block of queries, then the few references it
// cannot rank with certainty recomputed directly), in the same shape and order as
// ApproximateIndex::Search: exactly min(k, Nr) candidates per query. `threads` as above.
// Throws std::invalid_argument on k < 1, an empty reference set, or mismatched types/widths.
CandidateLists ExactNearest(const cv::Mat& references, const cv::Mat& queries, int k,
                            int threads = 0);

// Recall of approximate search against exact search, over the queries. Ties count: a
// candidate at the exact nearest distance is a nearest neighbour.
struct SearchRecall {
  // Share of queries whose first approximate candidate is at the exact nearest distance (the
  // nearest neighbour was found). As candidates are sorted by exact distance, this is also the
  // share whose nearest neighbour is anywhere among the approximate candidates.
  double top1 = 0;
  // Mean over queries of the share of the exact k nearest found: approximate candidates at a
  // distance <= the exact k-th distance, capped at k, over k (k = size of the exact list).
  double at_k = 0;
  int queries = 0;
};

// `exact` from ExactNearest and `approximate` from Search over the same queries and references.
// Throws std::invalid_argument when the list counts differ or an exact list is empty.
SearchRecall MeasureRecall(const CandidateLists& exact, const CandidateLists& approximate);

}  // namespace openable
