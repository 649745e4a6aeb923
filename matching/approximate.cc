#include "matching/approximate.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
// OpenCV's FLANN (namespace cvflann): its index templates are used directly, not through the
// type-erased cv::flann::Index, for const searches from several threads. See approximate.h for
// why not Debian's libflann. (opencv2/flann.hpp: the cvflann headers need its includes first.)
#include <opencv2/flann.hpp>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/threading.h"
#include "matching/distances.h"
#include "matching/faiss_index.h"

namespace openable {
namespace {

[[noreturn]] void Fail(const std::string& message) { throw std::invalid_argument(message); }

void CheckField(const char* field, long long value, long long lo, long long hi) {
  if (value < lo || value > hi)
    Fail(std::string("ApproximateOptions::") + field + " = " + std::to_string(value) +
         ", expected " + std::to_string(lo) + ".." + std::to_string(hi));
}

// Runs body(first, last) over [0, count) in blocks of `block` items on `threads` threads. The
// first exception thrown by a block is rethrown on the calling thread once all have stopped.
template <typename Body>
void ParallelBlocks(int count, int block, int threads, Body body) {
  const int blocks = (count + block - 1) / block;
  ParallelFor(blocks, threads,
              [&](int b) { body(b * block, std::min(count, (b + 1) * block)); });
}

// `m` must be a single-channel CV_8U or CV_32F matrix (finite values for CV_32F).
void CheckRows(const cv::Mat& m, const char* what) {
  if (m.channels() != 1 || (m.depth() != CV_8U && m.depth() != CV_32F))
    Fail(std::string(what) + ": expected CV_8UC1 or CV_32FC1 rows, got type " +
         std::to_string(m.type()));
  if (m.depth() == CV_32F && !m.empty() && !cv::checkRange(m, /*quiet=*/true))
    Fail(std::string(what) + ": NaN or infinite values");
}

// `queries` must match the references' type and width.
void CheckQueries(const cv::Mat& queries, int type, int width, const char* what) {
  CheckRows(queries, what);
  if (queries.empty()) return;
  if (queries.depth() != type || queries.cols != width)
    Fail(std::string(what) + ": queries of " + std::to_string(queries.cols) + " " +
         (queries.depth() == CV_8U ? "bytes" : "floats") + ", references of " +
         std::to_string(width) + " " + (type == CV_8U ? "bytes" : "floats"));
}

cv::Mat Continuous(const cv::Mat& m) { return m.isContinuous() ? m : m.clone(); }

// The order of CandidateLists: increasing distance, ties by increasing reference row.
bool CandidateBefore(const Candidate& a, const Candidate& b) {
  return a.distance < b.distance || (a.distance == b.distance && a.reference < b.reference);
}

void SortCandidates(std::vector<Candidate>& c) { std::sort(c.begin(), c.end(), CandidateBefore); }

// Queries handed to one FLANN call (and one thread) at a time.
constexpr int kQueryBlock = 32;

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

}  // namespace

bool FaissAvailable() {
#ifdef OPENABLE_HAVE_FAISS
  return true;
#else
  return false;
#endif
}

ApproximateEngine ResolvedEngine(ApproximateEngine engine, int depth) {
  if (engine != ApproximateEngine::kAuto) return engine;
  return depth == CV_8U ? ApproximateEngine::kIvf : ApproximateEngine::kHnsw;
}

void CheckEngineAvailable(ApproximateEngine engine, const std::string& key) {
  if (engine != ApproximateEngine::kFlann && !FaissAvailable())
    throw InputError(key + ": " + EnumName(engine) +
                     " needs FAISS, which this build does not have (libfaiss-dev and OpenMP were "
                     "not found when it was configured); expected flann");
}

void ApproximateOptions::Check() const {
  if (static_cast<int>(engine) < 0 || static_cast<size_t>(engine) >= EnumNames<ApproximateEngine>().size())
    Fail("ApproximateOptions::engine = " + std::to_string(static_cast<int>(engine)) +
         ", expected one of " + EnumChoices<ApproximateEngine>());
  CheckField("k", k, 1, std::numeric_limits<int>::max());
  CheckField("checks", checks, 1, std::numeric_limits<int>::max());
  CheckField("lsh_tables", lsh_tables, 1, 64);
  // Keys index a 2^bits bitset per table (FLANN's hash level): 24 bits is 2 MB a table.
  CheckField("lsh_key_bits", lsh_key_bits, 1, 24);
  // Level l probes sum_{i<=l} C(bits, i) keys per table: 1351 at level 3 with 20-bit keys.
  CheckField("lsh_probe_level", lsh_probe_level, 0, 3);
  CheckField("kd_trees", kd_trees, 1, 64);
  CheckField("hnsw_m", hnsw_m, 4, 128);
  CheckField("hnsw_ef_construction", hnsw_ef_construction, 8, 4096);
  CheckField("ef_search", ef_search, 1, 100000);
  CheckField("ivf_lists", ivf_lists, 0, std::numeric_limits<int>::max());
  CheckField("nprobe", nprobe, 1, 65536);
  CheckField("threads", threads, 0, 4096);
}

// Binary IVF: the cells FAISS trained and filled, scanned here with OpenABLE's Hamming
// kernels rather than by FAISS's search. Debian's libfaiss is built for baseline x86-64: its
// Hamming distances count bits without the POPCNT instruction (let alone AVX-512's
// VPOPCNTQ), several times slower per row than the kernels of matching/distances.h that the
// exact scan uses, which would eat most of what probing a few cells saves. The cells and the
// probing rule (the rows of the nprobe cells whose centres are nearest the query) are those of
// FAISS's IVF search; the distances are ours, exact, with ties broken by the lower cell and
// the lower row.
struct IvfCells {
  std::unique_ptr<HammingReferences> centres;             // one row per cell
  std::vector<std::unique_ptr<HammingReferences>> rows;   // each cell's rows (null: empty)
  std::vector<std::vector<int>> ids;                      // their rows of `references`
};

struct ApproximateIndex::Impl {
  using Lsh = cvflann::LshIndex<LshHamming>;
  using KdTrees = cvflann::KDTreeIndex<cvflann::L2<float>>;

  ApproximateOptions options;
  cv::Mat references;  // owned copy, continuous: the FLANN indices point into it
  std::unique_ptr<Lsh> lsh;
  std::unique_ptr<KdTrees> kd;
  std::unique_ptr<FaissIndex> faiss;  // hnsw, ivf (built in libopenable_faiss.so)

  std::unique_ptr<IvfCells> cells;  // binary ivf: see IvfCells
};

namespace {

// openable_matching reaches the FAISS module through ModuleSymbol (openable_io, linked
// PRIVATE: openable_io does not depend on this library, so there is no cycle) rather than a
// table of functions handed in by its callers: every caller (the pipeline, the online
// detector, the Python module, the benchmarks) then gets FAISS alike without wiring it.
FaissSettings SettingsOf(const ApproximateOptions& o, const cv::Mat& refs) {
  FaissSettings s;
  s.hnsw = o.engine == ApproximateEngine::kHnsw;
  s.binary = refs.depth() == CV_8U;
  s.width = refs.cols;
  s.hnsw_m = o.hnsw_m;
  s.hnsw_ef_construction = o.hnsw_ef_construction;
  s.ef_search = std::max(o.ef_search, o.k);
  s.ivf_lists = o.ivf_lists;
  s.nprobe = o.nprobe;
  s.threads = o.threads;
  s.seed = static_cast<int>(o.seed & 0x7FFFFFFFu);
  return s;
}

std::unique_ptr<FaissIndex> BuildFaiss(const ApproximateOptions& o, const cv::Mat& refs) {
  CheckEngineAvailable(o.engine, "ApproximateOptions::engine");
  const auto build =
      reinterpret_cast<OpenableFaissBuild>(ModuleSymbol("faiss", "openable_faiss_build"));
  return std::unique_ptr<FaissIndex>(build(SettingsOf(o, refs), refs.data, refs.rows));
}

// The index saved by Serialize(): FAISS's message (a damaged or foreign serialisation) and a
// row count that is not the references' become std::invalid_argument.
std::unique_ptr<FaissIndex> ReadFaiss(const ApproximateOptions& o, const cv::Mat& refs,
                                      const std::vector<std::uint8_t>& saved) {
  CheckEngineAvailable(o.engine, "ApproximateOptions::engine");
  const auto read =
      reinterpret_cast<OpenableFaissRead>(ModuleSymbol("faiss", "openable_faiss_read"));
  std::unique_ptr<FaissIndex> index;
  try {
    index.reset(read(SettingsOf(o, refs), saved.data(), saved.size()));
  } catch (const std::runtime_error& e) {
    Fail(std::string("ApproximateIndex: the saved index cannot be read: ") + e.what());
  }
  if (index->Size() != refs.rows)
    Fail("ApproximateIndex: the saved index holds " + std::to_string(index->Size()) +
         " rows, expected " + std::to_string(refs.rows) + " (its references)");
  return index;
}

// The cells of a binary IVF index (null for any other index), checked against the references:
// a saved index whose cells name rows it does not have is refused.
std::unique_ptr<IvfCells> CellsOf(const FaissIndex& index, const cv::Mat& refs) {
  std::vector<std::uint8_t> centres;
  std::vector<std::vector<std::int64_t>> cells;
  if (refs.depth() != CV_8U || !index.BinaryCells(&centres, &cells) || cells.empty()) return {};
  const std::size_t width = static_cast<std::size_t>(refs.cols);
  if (centres.size() != cells.size() * width)
    Fail("ApproximateIndex: the IVF index has " + std::to_string(centres.size()) +
         " bytes of cell centres, expected " + std::to_string(cells.size() * width));
  auto out = std::make_unique<IvfCells>();
  const cv::Mat centre_rows(static_cast<int>(cells.size()), refs.cols, CV_8U, centres.data());
  out->centres = std::make_unique<HammingReferences>(centre_rows);
  out->rows.resize(cells.size());
  out->ids.resize(cells.size());
  std::int64_t total = 0;
  for (std::size_t l = 0; l < cells.size(); ++l) {
    const std::vector<std::int64_t>& ids = cells[l];
    total += static_cast<std::int64_t>(ids.size());
    if (ids.empty()) continue;
    cv::Mat rows(static_cast<int>(ids.size()), refs.cols, CV_8U);
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] < 0 || ids[i] >= refs.rows)
        Fail("ApproximateIndex: the IVF index names row " + std::to_string(ids[i]) +
             ", expected 0 to " + std::to_string(refs.rows - 1));
      refs.row(static_cast<int>(ids[i])).copyTo(rows.row(static_cast<int>(i)));
      out->ids[l].push_back(static_cast<int>(ids[i]));
    }
    out->rows[l] = std::make_unique<HammingReferences>(rows);
  }
  if (total != refs.rows)
    Fail("ApproximateIndex: the IVF index's cells hold " + std::to_string(total) +
         " rows, expected " + std::to_string(refs.rows));
  return out;
}

}  // namespace

ApproximateIndex::ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options)
    : ApproximateIndex(references, options, {}) {}

ApproximateIndex::ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options,
                                   const std::vector<std::uint8_t>& saved)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  CheckRows(references, "ApproximateIndex");
  if (references.rows < 1 || references.cols < 1)
    Fail("ApproximateIndex: the reference set is empty");
  impl_->options = options;
  impl_->options.engine = ResolvedEngine(options.engine, references.depth());
  impl_->references = references.clone();
  cv::Mat& refs = impl_->references;

  // FLANN draws its random choices (LSH key bits, k-d tree shuffles and split dimensions) from
  // cv::theRNG() of this thread: seed it for a deterministic index, then give the caller's
  // generator back, even when the build throws.
  struct RestoreRng {
    cv::RNG saved = cv::theRNG();
    ~RestoreRng() { cv::theRNG() = saved; }
  } restore;
  cv::theRNG() = cv::RNG(options.seed);

  if (impl_->options.engine != ApproximateEngine::kFlann && !saved.empty()) {
    impl_->faiss = ReadFaiss(impl_->options, refs, saved);
  } else if (impl_->options.engine != ApproximateEngine::kFlann) {
    impl_->faiss = BuildFaiss(impl_->options, refs);
  }
  if (impl_->faiss) {
    impl_->cells = CellsOf(*impl_->faiss, refs);
  } else if (refs.depth() == CV_8U) {
    // A key cannot have more bits than the descriptor (FLANN would read past its bit list).
    const int key_bits = std::min(options.lsh_key_bits, 8 * refs.cols);
    const cvflann::Matrix<unsigned char> data(refs.ptr<unsigned char>(), refs.rows, refs.cols);
    impl_->lsh = std::make_unique<Impl::Lsh>(
        data, cvflann::LshIndexParams(options.lsh_tables, key_bits, options.lsh_probe_level));
    impl_->lsh->buildIndex();
  } else {
    const cvflann::Matrix<float> data(refs.ptr<float>(), refs.rows, refs.cols);
    impl_->kd = std::make_unique<Impl::KdTrees>(data, cvflann::KDTreeIndexParams(options.kd_trees));
    impl_->kd->buildIndex();
  }
}

ApproximateIndex::~ApproximateIndex() = default;
ApproximateIndex::ApproximateIndex(ApproximateIndex&&) noexcept = default;
ApproximateIndex& ApproximateIndex::operator=(ApproximateIndex&&) noexcept = default;

int ApproximateIndex::Size() const { return impl_->references.rows; }
int ApproximateIndex::Width() const { return impl_->references.cols; }
int ApproximateIndex::Type() const { return impl_->references.depth(); }
const ApproximateOptions& ApproximateIndex::Options() const { return impl_->options; }

void ApproximateIndex::SetSearchBudget(const ApproximateOptions& options) {
  options.Check();
  impl_->options.checks = options.checks;
  impl_->options.ef_search = options.ef_search;
  impl_->options.nprobe = options.nprobe;
  if (impl_->faiss)
    impl_->faiss->SetSearch(std::max(options.ef_search, impl_->options.k), options.nprobe);
}

std::vector<std::uint8_t> ApproximateIndex::Serialize() const {
  return impl_->faiss ? impl_->faiss->Serialize() : std::vector<std::uint8_t>{};
}

CandidateLists ApproximateIndex::Search(const cv::Mat& queries_in) const {
  const cv::Mat& refs = impl_->references;
  CheckQueries(queries_in, refs.depth(), refs.cols, "ApproximateIndex::Search");
  CandidateLists out(static_cast<size_t>(queries_in.rows));
  if (queries_in.empty()) return out;
  const cv::Mat queries = Continuous(queries_in);
  // FLANN's k-d tree search insists on filling k slots, so k is capped at the set size.
  const int knn = std::min(impl_->options.k, refs.rows);
  const cvflann::SearchParams params(impl_->options.checks);

  if (impl_->cells) {
    // The nprobe cells whose centres are nearest the query (ties: the lower cell), then the k
    // nearest of their rows (ties: the lower row), kept in a max-heap of k.
    const IvfCells& cells = *impl_->cells;
    const int lists = static_cast<int>(cells.ids.size());
    const int probes = std::min(impl_->options.nprobe, lists);
    ParallelBlocks(queries.rows, kQueryBlock, impl_->options.threads, [&](int q0, int q1) {
      std::vector<float> centre(static_cast<size_t>(lists)), d;
      std::vector<int> order(static_cast<size_t>(lists));
      for (int q = q0; q < q1; ++q) {
        const std::uint8_t* query = queries.ptr<std::uint8_t>(q);
        cells.centres->Distances(query, centre.data());
        std::iota(order.begin(), order.end(), 0);
        std::partial_sort(order.begin(), order.begin() + probes, order.end(), [&](int a, int b) {
          return centre[static_cast<size_t>(a)] < centre[static_cast<size_t>(b)] ||
                 (centre[static_cast<size_t>(a)] == centre[static_cast<size_t>(b)] && a < b);
        });
        std::vector<Candidate>& heap = out[static_cast<size_t>(q)];
        heap.reserve(static_cast<size_t>(knn));
        for (int p = 0; p < probes; ++p) {
          const int l = order[static_cast<size_t>(p)];
          const std::vector<int>& ids = cells.ids[static_cast<size_t>(l)];
          if (ids.empty()) continue;
          d.resize(ids.size());
          cells.rows[static_cast<size_t>(l)]->Distances(query, d.data());
          for (std::size_t i = 0; i < ids.size(); ++i) {
            const Candidate c{ids[i], d[i]};
            if (static_cast<int>(heap.size()) < knn) {
              heap.push_back(c);
              std::push_heap(heap.begin(), heap.end(), CandidateBefore);
            } else if (CandidateBefore(c, heap.front())) {
              std::pop_heap(heap.begin(), heap.end(), CandidateBefore);
              heap.back() = c;
              std::push_heap(heap.begin(), heap.end(), CandidateBefore);
            }
          }
        }
        SortCandidates(heap);
      }
    });
    return out;
  }

  if (impl_->faiss) {
    // FAISS spreads the queries over its OpenMP threads itself; only the exact distances are
    // recomputed here, over OpenABLE's.
    std::vector<std::int64_t> labels(static_cast<size_t>(queries.rows) * static_cast<size_t>(knn));
    impl_->faiss->Search(queries.data, queries.rows, knn, labels.data());
    ParallelBlocks(queries.rows, kQueryBlock, impl_->options.threads, [&](int q0, int q1) {
      for (int q = q0; q < q1; ++q) {
        std::vector<Candidate>& list = out[static_cast<size_t>(q)];
        for (int i = 0; i < knn; ++i) {
          const std::int64_t r = labels[static_cast<size_t>(q) * static_cast<size_t>(knn) +
                                        static_cast<size_t>(i)];
          if (r < 0 || r >= refs.rows) continue;
          const int row = static_cast<int>(r);
          list.push_back(Candidate{row, RowDistance(refs, row, queries, q)});
        }
        SortCandidates(list);
      }
    });
    return out;
  }

  // FLANN's search reads the index only (its k-d tree heaps are pooled per thread id), so
  // blocks of queries run in parallel on the one index, each thread with its own result set.
  ParallelBlocks(queries.rows, kQueryBlock, impl_->options.threads, [&](int q0, int q1) {
    if (impl_->lsh) {
      KnnUnique<int> result(knn, refs.rows);
      for (int q = q0; q < q1; ++q) {
        result.Start();
        impl_->lsh->findNeighbors(result, queries.ptr<unsigned char>(q), params);
        result.CopyTo(out[static_cast<size_t>(q)]);
      }
    } else {
      KnnUnique<float> result(knn, refs.rows);
      for (int q = q0; q < q1; ++q) {
        result.Start();
        impl_->kd->findNeighbors(result, queries.ptr<float>(q), params);
        result.CopyTo(out[static_cast<size_t>(q)]);
      }
    }
    // FLANN's distances are squared (L2): recompute the exact ones and sort.
    for (int q = q0; q < q1; ++q) {
      std::vector<Candidate>& list = out[static_cast<size_t>(q)];
      for (Candidate& c : list) c.distance = RowDistance(refs, c.reference, queries, q);
      SortCandidates(list);
    }
  });
  return out;
}

namespace {

// Hamming: every distance of a query from the popcount kernel, then the references up to the
// k-th distance (a histogram of bit counts finds it) sorted.
void ExactHamming(const cv::Mat& refs, const cv::Mat& queries, int k, int threads,
                  CandidateLists& out) {
  const HammingReferences packed(refs);
  const int max_bits = 8 * refs.cols;
  ParallelBlocks(queries.rows, kQueryBlock, threads, [&](int q0, int q1) {
    std::vector<float> d(static_cast<size_t>(refs.rows));
    std::vector<int> histogram(static_cast<size_t>(max_bits) + 1);
    for (int q = q0; q < q1; ++q) {
      packed.Distances(queries.ptr<std::uint8_t>(q), d.data());
      std::fill(histogram.begin(), histogram.end(), 0);
      for (const float v : d) ++histogram[static_cast<size_t>(v)];
      int kth = 0;
      for (int seen = 0; kth <= max_bits; ++kth)
        if ((seen += histogram[static_cast<size_t>(kth)]) >= k) break;
      std::vector<Candidate>& list = out[static_cast<size_t>(q)];
      for (int r = 0; r < refs.rows; ++r)
        if (d[static_cast<size_t>(r)] <= static_cast<float>(kth))
          list.push_back(Candidate{r, d[static_cast<size_t>(r)]});
      SortCandidates(list);
      list.resize(static_cast<size_t>(k));
    }
  });
}

// L2: squared distances for a block of queries from one matrix product, |q|^2 + |r|^2 - 2 q.r,
// in float. Its error is bounded (every dot product of d terms is within d u sum|q_i r_i| of the
// truth, u = 2^-24, and sum|q_i r_i| <= (|q|^2 + |r|^2) / 2), so each cell is known to lie in
// [lower, upper] with a margin (2 d + 8) u (|q|^2 + |r|^2). The k-th smallest upper bound bounds
// the k-th distance; every reference whose lower bound is below it is recomputed exactly and
// the k best of those kept. The result is the exact k nearest, at the cost of one product.
void ExactL2(const cv::Mat& refs, const cv::Mat& queries, int k, int threads, CandidateLists& out) {
  using RowMat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const int n = refs.rows, d = refs.cols;
  const Eigen::Map<const RowMat> r(refs.ptr<float>(), n, d);
  const Eigen::VectorXf r_norms = r.rowwise().squaredNorm();
  const float margin =
      1.01f * static_cast<float>(2 * d + 8) * std::numeric_limits<float>::epsilon() / 2;
  ParallelBlocks(queries.rows, kQueryBlock, threads, [&](int q0, int q1) {
    const Eigen::Map<const RowMat> q(queries.ptr<float>(q0), q1 - q0, d);
    const RowMat g = q * r.transpose();
    std::vector<float> lower(static_cast<size_t>(n)), upper(static_cast<size_t>(n));
    for (int i = 0; i < q1 - q0; ++i) {
      const float q_norm = q.row(i).squaredNorm();
      for (int j = 0; j < n; ++j) {
        const float scale = q_norm + r_norms[j];
        const float sq = scale - 2.0f * g(i, j);
        const float tol = margin * scale;
        lower[static_cast<size_t>(j)] = sq - tol;
        upper[static_cast<size_t>(j)] = sq + tol;
      }
      std::vector<float> sorted_upper = upper;
      std::nth_element(sorted_upper.begin(), sorted_upper.begin() + (k - 1), sorted_upper.end());
      // Slack for the rounding of the returned distance to float.
      const float bound = sorted_upper[static_cast<size_t>(k - 1)] *
                          (1.0f + 4.0f * std::numeric_limits<float>::epsilon());
      std::vector<Candidate>& list = out[static_cast<size_t>(q0 + i)];
      for (int j = 0; j < n; ++j)
        if (lower[static_cast<size_t>(j)] <= bound)
          list.push_back(
              Candidate{j, L2Distance(queries.ptr<float>(q0 + i), refs.ptr<float>(j), d)});
      SortCandidates(list);
      list.resize(static_cast<size_t>(k));
    }
  });
}

}  // namespace

CandidateLists ExactNearest(const cv::Mat& references, const cv::Mat& queries_in, int k,
                            int threads) {
  if (k < 1) Fail("ExactNearest: k = " + std::to_string(k) + ", expected >= 1");
  if (threads < 0) Fail("ExactNearest: threads = " + std::to_string(threads) + ", expected >= 0");
  CheckRows(references, "ExactNearest");
  if (references.rows < 1 || references.cols < 1) Fail("ExactNearest: the reference set is empty");
  CheckQueries(queries_in, references.depth(), references.cols, "ExactNearest");
  CandidateLists out(static_cast<size_t>(queries_in.rows));
  if (queries_in.empty()) return out;
  const cv::Mat refs = Continuous(references), queries = Continuous(queries_in);
  const int kk = std::min(k, refs.rows);
  if (refs.depth() == CV_8U)
    ExactHamming(refs, queries, kk, threads, out);
  else
    ExactL2(refs, queries, kk, threads, out);
  return out;
}

SearchRecall MeasureRecall(const CandidateLists& exact, const CandidateLists& approximate) {
  if (exact.size() != approximate.size())
    Fail("MeasureRecall: " + std::to_string(exact.size()) + " exact lists, " +
         std::to_string(approximate.size()) + " approximate");
  SearchRecall recall;
  recall.queries = static_cast<int>(exact.size());
  if (exact.empty()) return recall;
  double top1 = 0, at_k = 0;
  for (size_t q = 0; q < exact.size(); ++q) {
    const std::vector<Candidate>& e = exact[q];
    const std::vector<Candidate>& a = approximate[q];
    if (e.empty()) Fail("MeasureRecall: empty exact list for query " + std::to_string(q));
    if (!a.empty() && a.front().distance <= e.front().distance) top1 += 1;
    const float kth = e.back().distance;
    const size_t found = static_cast<size_t>(
        std::count_if(a.begin(), a.end(), [&](const Candidate& c) { return c.distance <= kth; }));
    at_k += static_cast<double>(std::min(found, e.size())) / static_cast<double>(e.size());
  }
  recall.top1 = top1 / static_cast<double>(exact.size());
  recall.at_k = at_k / static_cast<double>(exact.size());
  return recall;
}

}  // namespace openable
