#include "matching/search/approximate.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "OpenABLE/base/error.h"
#include "matching/distances.h"
#include "matching/search/approximate_engine.h"

namespace openable {
namespace {

[[noreturn]] void Fail(const std::string& message) { throw std::invalid_argument(message); }

void CheckField(const char* field, int value, ApproximateRange range) {
  if (value < range.min || value > range.max)
    Fail(std::string("ApproximateOptions::") + field + " = " + std::to_string(value) +
         ", expected " + std::to_string(range.min) + ".." + std::to_string(range.max));
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

}  // namespace

void ApproximateOptions::Check() const {
  if (!IsApproximateEngine(engine))
    Fail("ApproximateOptions::engine = " + Quoted(engine) + ", expected one of " +
         ApproximateEngineChoices());
  CheckField("k", k, kKRange);
  CheckField("checks", checks, kChecksRange);
  CheckField("lsh_tables", lsh_tables, kLshTablesRange);
  CheckField("lsh_key_bits", lsh_key_bits, kLshKeyBitsRange);
  CheckField("lsh_probe_level", lsh_probe_level, kLshProbeLevelRange);
  CheckField("kd_trees", kd_trees, kKdTreesRange);
  CheckField("hnsw_m", hnsw_m, kHnswMRange);
  CheckField("hnsw_ef_construction", hnsw_ef_construction, kHnswEfConstructionRange);
  CheckField("ef_search", ef_search, kEfSearchRange);
  CheckField("ivf_lists", ivf_lists, kIvfListsRange);
  CheckField("nprobe", nprobe, kNprobeRange);
  CheckField("threads", threads, kThreadsRange);
}

struct ApproximateIndex::Impl {
  ApproximateOptions options;  // engine resolved
  cv::Mat references;          // owned copy, continuous: the engine's index may point into it
                               // (released once built when the engine owns its rows)
  int rows = 0, width = 0, type = CV_8U;  // of the references
  std::unique_ptr<EngineIndex> index;
};

ApproximateIndex::ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options)
    : ApproximateIndex(references, options, {}) {}

ApproximateIndex::ApproximateIndex(const cv::Mat& references, const ApproximateOptions& options,
                                   const SavedIndex& saved)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  CheckRows(references, "ApproximateIndex");
  if (references.rows < 1 || references.cols < 1)
    Fail("ApproximateIndex: the reference set is empty");
  impl_->options = options;
  impl_->options.engine = ResolvedEngine(options.engine, references.depth());
  CheckEngineAvailable(impl_->options.engine, "ApproximateOptions::engine");
  const ApproximateEngineEntry& entry =
      FindApproximateEngine(impl_->options.engine, references.depth());
  if (entry.binary_only && references.depth() != CV_8U)
    Fail(std::string("ApproximateOptions::engine = ") + entry.name +
         " indexes binary rows only; expected binary descriptors (LDB, ORB, BRISK, FREAK, "
         "BRIEF) or another engine for float rows");
  // An index read in place from bytes that outlive it reads the references during the build
  // only (the engine keeps what it needs): no copy of them is made.
  const bool in_place = saved.owner && entry.owns_rows;
  impl_->references = in_place ? Continuous(references) : references.clone();
  impl_->index = entry.build(impl_->references, impl_->options, saved);
  impl_->rows = references.rows;
  impl_->width = references.cols;
  impl_->type = references.depth();
  if (entry.owns_rows) impl_->references.release();
}

ApproximateIndex::~ApproximateIndex() = default;
ApproximateIndex::ApproximateIndex(ApproximateIndex&&) noexcept = default;
ApproximateIndex& ApproximateIndex::operator=(ApproximateIndex&&) noexcept = default;

int ApproximateIndex::Size() const { return impl_->rows; }
int ApproximateIndex::Width() const { return impl_->width; }
int ApproximateIndex::Type() const { return impl_->type; }
const ApproximateOptions& ApproximateIndex::Options() const { return impl_->options; }

void ApproximateIndex::SetSearchBudget(const ApproximateOptions& options) {
  options.Check();
  impl_->options.checks = options.checks;
  impl_->options.ef_search = options.ef_search;
  impl_->options.nprobe = options.nprobe;
  impl_->index->SetSearchBudget(impl_->options);
}

std::vector<std::uint8_t> ApproximateIndex::Serialize() const { return impl_->index->Serialize(); }

CandidateLists ApproximateIndex::Search(const cv::Mat& queries) const {
  CheckQueries(queries, impl_->type, impl_->width, "ApproximateIndex::Search");
  if (queries.empty()) return CandidateLists(static_cast<size_t>(queries.rows));
  return impl_->index->Search(Continuous(queries), impl_->options);
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
