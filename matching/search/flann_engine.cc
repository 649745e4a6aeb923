#include "matching/search/flann_engine.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>
// OpenCV's FLANN (namespace cvflann): its index templates are used directly, not through the
// type-erased cv::flann::Index, for const searches from several threads. See flann_engine.h for
// why not Debian's libflann. (opencv2/flann.hpp: the cvflann headers need its includes first.)
#include <opencv2/flann.hpp>

#include "matching/distances.h"

namespace openable {
namespace {

// FLANN's Hamming functor on HammingDistance, which uses the popcount instruction when the CPU
// has it: FLANN's own cvflann::Hamming is compiled for baseline x86-64 here, where
// __builtin_popcountll becomes a bit-twiddling routine. The LSH index scores every candidate of
// every probed bucket with it.
struct LshHamming {
  using ElementType = unsigned char;
  using ResultType = int;
  using is_kdtree_distance = cvflann::False;
  using is_vector_space_distance = cvflann::False;
  template <typename A, typename B>
  ResultType operator()(A a, B b, size_t size, ResultType /*worst*/ = -1) const {
    return HammingDistance(reinterpret_cast<const std::uint8_t*>(a),
                           reinterpret_cast<const std::uint8_t*>(b), static_cast<int>(size));
  }
};

// FLANN result set: the k best (distance, reference) pairs offered, each reference once.
// FLANN's own KNNUniqueResultSet keeps a std::set; here a stamp per reference drops repeats
// (LSH offers a reference once per table and probe that holds it) and a small sorted array
// keeps the k best, ties broken by reference so that the kept set does not depend on the
// order FLANN offers them in.
template <typename Distance>
class KnnUnique final : public cvflann::ResultSet<Distance> {
 public:
  KnnUnique(int k, int references)
      : k_(static_cast<size_t>(k)), stamp_(static_cast<size_t>(references), 0) {
    best_.reserve(k_ + 1);
  }
  void Start() {
    best_.clear();
    if (++epoch_ == 0) {  // wrapped: forget every stamp
      std::fill(stamp_.begin(), stamp_.end(), 0);
      epoch_ = 1;
    }
  }
  bool full() const override { return best_.size() == k_; }
  Distance worstDist() const override {
    return full() ? best_.back().first : std::numeric_limits<Distance>::max();
  }
  void addPoint(Distance dist, int index) override {
    const std::pair<Distance, int> p(dist, index);
    if (full() && !(p < best_.back())) return;
    std::uint32_t& stamp = stamp_[static_cast<size_t>(index)];
    if (stamp == epoch_) return;
    stamp = epoch_;
    best_.insert(std::upper_bound(best_.begin(), best_.end(), p), p);
    if (best_.size() > k_) best_.pop_back();
  }
  // The kept references into `out`, with FLANN's distances (the caller replaces them).
  void CopyTo(std::vector<Candidate>& out) const {
    out.clear();
    for (const auto& [dist, index] : best_)
      out.push_back(Candidate{index, static_cast<float>(dist)});
  }

 private:
  size_t k_;
  std::vector<std::pair<Distance, int>> best_;  // sorted, at most k_
  std::vector<std::uint32_t> stamp_;            // epoch_ when the reference was last offered
  std::uint32_t epoch_ = 0;
};

// LSH tables (binary rows) or k-d trees (float rows) over the references.
class FlannIndex final : public EngineIndex {
 public:
  FlannIndex(const cv::Mat& references, const ApproximateOptions& options) : refs_(references) {
    // FLANN draws its random choices (LSH key bits, k-d tree shuffles and split dimensions)
    // from cv::theRNG() of this thread: seed it for a deterministic index, then give the
    // caller's generator back, even when the build throws.
    struct RestoreRng {
      cv::RNG saved = cv::theRNG();
      ~RestoreRng() { cv::theRNG() = saved; }
    } restore;
    cv::theRNG() = cv::RNG(options.seed);
    if (refs_.depth() == CV_8U) {
      // A key cannot have more bits than the descriptor (FLANN would read past its bit list).
      const int key_bits = std::min(options.lsh_key_bits, 8 * refs_.cols);
      const cvflann::Matrix<unsigned char> data(refs_.ptr<unsigned char>(), refs_.rows, refs_.cols);
      lsh_ = std::make_unique<Lsh>(
          data, cvflann::LshIndexParams(options.lsh_tables, key_bits, options.lsh_probe_level));
      lsh_->buildIndex();
    } else {
      const cvflann::Matrix<float> data(refs_.ptr<float>(), refs_.rows, refs_.cols);
      kd_ = std::make_unique<KdTrees>(data, cvflann::KDTreeIndexParams(options.kd_trees));
      kd_->buildIndex();
    }
  }

  CandidateLists Search(const cv::Mat& queries, const ApproximateOptions& options) const override {
    CandidateLists out(static_cast<size_t>(queries.rows));
    // FLANN's k-d tree search insists on filling k slots, so k is capped at the set size.
    const int knn = std::min(options.k, refs_.rows);
    const cvflann::SearchParams params(options.checks);
    // FLANN's search reads the index only (its k-d tree heaps are pooled per thread id), so
    // blocks of queries run in parallel on the one index, each thread with its own result set.
    ParallelBlocks(queries.rows, kQueryBlock, options.threads, [&](int q0, int q1) {
      if (lsh_) {
        KnnUnique<int> result(knn, refs_.rows);
        for (int q = q0; q < q1; ++q) {
          result.Start();
          lsh_->findNeighbors(result, queries.ptr<unsigned char>(q), params);
          result.CopyTo(out[static_cast<size_t>(q)]);
        }
      } else {
        KnnUnique<float> result(knn, refs_.rows);
        for (int q = q0; q < q1; ++q) {
          result.Start();
          kd_->findNeighbors(result, queries.ptr<float>(q), params);
          result.CopyTo(out[static_cast<size_t>(q)]);
        }
      }
      // FLANN's distances are squared (L2): recompute the exact ones and sort.
      for (int q = q0; q < q1; ++q) {
        std::vector<Candidate>& list = out[static_cast<size_t>(q)];
        for (Candidate& c : list) c.distance = RowDistance(refs_, c.reference, queries, q);
        SortCandidates(list);
      }
    });
    return out;
  }

 private:
  using Lsh = cvflann::LshIndex<LshHamming>;
  using KdTrees = cvflann::KDTreeIndex<cvflann::L2<float>>;

  cv::Mat refs_;  // a header of ApproximateIndex's rows: the FLANN indices point into them
  std::unique_ptr<Lsh> lsh_;
  std::unique_ptr<KdTrees> kd_;
};

// FLANN's structure is not serialised: `saved` (empty) is not read.
std::unique_ptr<EngineIndex> Build(const cv::Mat& references, const ApproximateOptions& options,
                                   const SavedIndex& /*saved*/) {
  return std::make_unique<FlannIndex>(references, options);
}

// Counted as one more copy of the rows: LSH's 12 tables of one 4-byte id per row is less, 4
// k-d trees of nodes per row about that.
std::int64_t BytesPerRow(const ApproximateOptions& /*options*/, int /*depth*/,
                         std::int64_t row_bytes) {
  return row_bytes;
}

}  // namespace

const ApproximateEngineEntry kFlannEngine = {
    "flann",                                                                   // name
    "OpenCV's FLANN (LSH for binary descriptors, k-d trees for vector ones)",  // summary
    /*needs_faiss=*/false,
    /*binary_only=*/false,
    /*owns_rows=*/false,
    &Build,
    &BytesPerRow,
};

}  // namespace openable
