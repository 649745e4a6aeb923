// Approximate candidate search for very large reference sets: the k nearest references of each
// query found by one of three engines, and the exact search they are measured against.
//
//  - flann: OpenCV's FLANN, LSH for binary descriptors (Hamming) and randomised k-d trees for
//    vector descriptors (L2).
//  - hnsw: FAISS's hierarchical navigable small-world graphs, IndexBinaryHNSW (Hamming) and
//    IndexHNSWFlat (L2). Y. A. Malkov and D. A. Yashunin, "Efficient and robust approximate
//    nearest neighbor search using Hierarchical Navigable Small World graphs", IEEE T-PAMI
//    42(4), 2020.
//  - ivf: FAISS's inverted files, IndexBinaryIVF (Hamming) and IndexIVFFlat (L2): k-means
//    cells, `nprobe` nearest cells scanned exhaustively. J. Sivic and A. Zisserman, "Video
//    Google", ICCV 2003; J. Johnson, M. Douze and H. Jegou, "Billion-scale similarity search
//    with GPUs", IEEE T-BD 7(3), 2021 (FAISS).
//
// FAISS (libfaiss-dev, with OpenMP and BLAS) is compiled into the run-time module
// libopenable_faiss.so (matching/faiss_module.cc, OpenABLE/base/module_loader.h), loaded when
// the first FAISS index is built: a run that uses FLANN or exact search does not load libgomp,
// BLAS or LAPACK. A build configured without FAISS refuses hnsw and ivf (FaissAvailable()).
//
// Papers: M. Muja and D. G. Lowe, "Scalable Nearest Neighbor Algorithms for High Dimensional
// Data", IEEE T-PAMI 36(11), 2014 (randomised k-d trees, best-bin-first with a budget of
// `checks` leaves); Q. Lv et al., "Multi-Probe LSH", VLDB 2007 (LSH tables probed at
// neighbouring keys), as FLANN implements them.
//
// The FLANN used is OpenCV's copy (module opencv_flann, namespace cvflann), not Debian's
// libflann 1.9.2: that build seeds its LSH bit selection and its k-d tree shuffles from
// std::random_device, so two runs on the same data give different candidates, and it cannot
// be made deterministic; OpenCV's copy draws from cv::theRNG(), which is seeded here.
//
// Every distance returned is exact, recomputed for the pair after the search by RowDistance
// (matching/distances.h): the number of differing bits, or the Euclidean (not squared) distance
// summed in double precision and rounded to float. Exact and approximate results therefore give
// equal distances for equal pairs, and recall can compare them with ==.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable {

// The engine of ApproximateIndex (the key Approximate_engine), see above.
// auto (the default): ivf for binary rows, hnsw for float rows, the faster for a given recall
// on each kind in bench/bench_approximate (docs/matching.md, "Choosing an engine").
enum class ApproximateEngine { kFlann, kHnsw, kIvf, kAuto };
OPENABLE_ENUM_NAMES(ApproximateEngine, "flann", "hnsw", "ivf", "auto")

// The engine `engine` stands for on rows of OpenCV depth `depth`: auto becomes ivf for CV_8U
// and hnsw otherwise; the others are themselves.
ApproximateEngine ResolvedEngine(ApproximateEngine engine, int depth);

// Whether this build has FAISS (the hnsw and ivf engines): false when libfaiss-dev or OpenMP
// was not found when the build was configured.
bool FaissAvailable();
// Throws InputError "<key>: <engine> needs FAISS, which this build does not have (...);
// expected flann" when `engine` is a FAISS engine and FaissAvailable() is false.
void CheckEngineAvailable(ApproximateEngine engine, const std::string& key);

// One candidate reference of a query.
struct Candidate {
  int reference = -1;  // row of the reference set
  float distance = 0;  // Hamming bit count (CV_8U rows) or Euclidean distance (CV_32F rows)
};

// Candidates of each query, sorted by increasing distance, ties by increasing reference row.
using CandidateLists = std::vector<std::vector<Candidate>>;

// Defaults, from bench/bench_approximate.cc on Nordland winter queries against 50,000 summer
// and distractor references (docs/benchmarks.md): LSH 12 tables of 20-bit keys probed at level
// 2 (FLANN's usual setting for binary descriptors) finds the exact nearest LDB row for ~80 %
// of queries; 4 k-d trees with 512 checks give HOG ~14x the speed of exact search while the
// share of queries matched to the right place drops by ~2 points (128 checks: ~7 points).
struct ApproximateOptions {
  ApproximateEngine engine = ApproximateEngine::kAuto;
  int k = 10;             // candidates per query, >= 1; more than the references gives them all
  int checks = 512;       // k-d trees: references examined per query (best bin first), >= 1; more =
                          // better recall, slower. LSH ignores it (it reads every probed bucket).
  int lsh_tables = 12;    // LSH: hash tables, 1..64; more = better recall, slower
  int lsh_key_bits = 20;  // LSH: bits of a table's key, 1..24 (capped at the descriptor's
                          // bits); fewer = larger buckets, better recall, slower
  int lsh_probe_level = 2;  // LSH multi-probe: also read the buckets of keys within this many
                            // flipped bits, 0..3 (level 2 reads 211 buckets a table at 20 bits)
  int kd_trees = 4;         // randomised k-d trees, 1..64
  // HNSW: neighbours per node and layer (M of the paper; 2 M on the bottom layer), 4..128.
  int hnsw_m = 32;
  // HNSW: candidate list while inserting (efConstruction), 8..4096; more = better graph,
  // slower build.
  int hnsw_ef_construction = 64;
  // HNSW: candidate list while searching (efSearch), 1..100000, raised to k when smaller;
  // more = better recall, slower.
  int ef_search = 128;
  // IVF: k-means cells; 0 = automatic, 2 sqrt(Nr) capped at Nr / 39 (FAISS's minimum of 39
  // training rows a cell), at least 1. Otherwise 1..Nr.
  int ivf_lists = 0;
  // IVF: cells scanned per query (nprobe), 1..65536 (capped at the cells); more = better
  // recall, slower.
  int nprobe = 64;
  int threads = 0;          // queries spread over this many threads, >= 0 (0 = all cores)
  // Seed of the index build: cv::RNG of FLANN ("FLAN"); FAISS's IVF k-means takes its low 31
  // bits (HNSW levels are drawn from FAISS's fixed seed, and its rows are added on one thread,
  // which makes the graph deterministic).
  std::uint64_t seed = 0x464C414EULL;

  // Throws std::invalid_argument naming the field, the value and the valid range.
  void Check() const;
};

// An index over a fixed set of references (rows of one CV_8UC1 or CV_32FC1 matrix).
class ApproximateIndex {
 public:
  // Copies `references` (Nr x W, Nr >= 1) and builds the index of options.engine: LSH or
  // binary HNSW/IVF for CV_8U, k-d trees or float HNSW/IVF for CV_32F. Deterministic for
  // given references and options (FLANN draws from cv::theRNG() of the calling thread, seeded
  // with options.seed and restored afterwards; FAISS as ApproximateOptions::seed says). Throws
  // std::invalid_argument (a std::logic_error) on bad options, an empty set, another type, or
  // non-finite floats; InputError when a FAISS engine is asked of a build without FAISS.
  ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options);
  // The index of `references` from `saved`, bytes of Serialize() of an index built over the
  // same references with the same options: FAISS's structure is read, not built again (a
  // million-row HNSW graph takes minutes to build, a second to read); FLANN's, whose
  // Serialize() is empty, is built (deterministic, so the same index). Throws
  // std::invalid_argument when the bytes hold another kind of index or another row count.
  ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options,
                   const std::vector<std::uint8_t>& saved);
  ~ApproximateIndex();
  ApproximateIndex(ApproximateIndex&&) noexcept;
  ApproximateIndex& operator=(ApproximateIndex&&) noexcept;
  ApproximateIndex(const ApproximateIndex&) = delete;
  ApproximateIndex& operator=(const ApproximateIndex&) = delete;

  // Up to options.k candidates for every row of `queries` (Nq x W, the references' type and
  // width; Nq may be 0), exact distances, sorted as CandidateLists says. LSH may return fewer
  // than k when few references share a probed bucket with the query (none at all is possible),
  // IVF when the probed cells hold fewer than k rows; k-d trees and HNSW return min(k, Nr).
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
  // (write_index / write_index_binary, including FAISS's own copy of the rows); empty for
  // FLANN, whose LSH tables and k-d trees are rebuilt from the rows in milliseconds to seconds.
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
