#include "matching/search/faiss_engines.h"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/module_loader.h"
#include "matching/blas.h"
#include "matching/distances.h"
#include "matching/search/faiss_index.h"
#include "matching/search/ivf_cells.h"

namespace openable {
namespace {

[[noreturn]] void FailFaiss(const std::string& message) { throw std::invalid_argument(message); }

// Binary IVF: the cells FAISS trained and filled, scanned here with OpenABLE's Hamming
// kernels rather than by FAISS's search (IvfCells, matching/search/ivf_cells.h). Debian's
// libfaiss is built for baseline x86-64: its Hamming distances count bits without the POPCNT
// instruction (let alone AVX-512's VPOPCNTQ), several times slower per row than the kernels
// of matching/distances.h that the exact scan uses, which would eat most of what probing a
// few cells saves. The cells and the probing rule are those of FAISS's IVF search; the
// distances are ours, exact, with ties broken by the lower cell and the lower row.

// The module's settings of an index of `options` over `refs`: the one place FaissSettings are
// made, every field from ApproximateOptions or the rows.
//
// openable_matching reaches the FAISS module through ModuleSymbol (base/module_loader.h) rather
// than a table of functions handed in by its callers: every caller (the pipeline, the online
// detector, the Python module, the benchmarks) then gets FAISS alike without wiring it.
FaissSettings SettingsOf(const ApproximateOptions& o, const cv::Mat& refs, bool hnsw) {
  FaissSettings s{};
  s.hnsw = hnsw;
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

std::unique_ptr<FaissIndex> BuildFaiss(const ApproximateOptions& o, const cv::Mat& refs,
                                       bool hnsw) {
  // FAISS trains IVF cells by float k-means on OpenBLAS, spread over its OpenMP threads, each
  // calling sgemm: OpenBLAS then runs this CPU's kernels (on a CPU newer than Debian's OpenBLAS
  // it ran its slow SSE3 ones; docs/benchmarks.md, "Large maps") on one thread (its own
  // threads competed with FAISS's for the cores).
  const BlasOnOneThread one_thread;
  const auto build =
      reinterpret_cast<OpenableFaissBuild>(ModuleSymbol("faiss", "openable_faiss_build"));
  return std::unique_ptr<FaissIndex>(build(SettingsOf(o, refs, hnsw), refs.data, refs.rows));
}

// The index saved by Serialize(): FAISS's message (a damaged or foreign serialisation) and a
// row count that is not the references' become std::invalid_argument.
std::unique_ptr<FaissIndex> ReadFaiss(const ApproximateOptions& o, const cv::Mat& refs, bool hnsw,
                                      const SavedIndex& saved) {
  const auto read =
      reinterpret_cast<OpenableFaissRead>(ModuleSymbol("faiss", "openable_faiss_read"));
  std::unique_ptr<FaissIndex> index;
  try {
    index.reset(read(SettingsOf(o, refs, hnsw), saved.data, saved.size));
  } catch (const std::runtime_error& e) {
    FailFaiss(std::string("ApproximateIndex: the saved index cannot be read: ") + e.what());
  }
  if (index->Size() != refs.rows)
    FailFaiss("ApproximateIndex: the saved index holds " + std::to_string(index->Size()) +
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
    FailFaiss("ApproximateIndex: the IVF index has " + std::to_string(centres.size()) +
              " bytes of cell centres, expected " + std::to_string(cells.size() * width));
  std::vector<std::vector<int>> ids(cells.size());
  for (std::size_t l = 0; l < cells.size(); ++l)
    for (const std::int64_t id : cells[l]) {
      if (id < 0 || id >= refs.rows)
        FailFaiss("ApproximateIndex: the IVF index names row " + std::to_string(id) +
                  ", expected 0 to " + std::to_string(refs.rows - 1));
      ids[l].push_back(static_cast<int>(id));
    }
  const cv::Mat centre_rows(static_cast<int>(cells.size()), refs.cols, CV_8U, centres.data());
  try {
    return MakeIvfCells(refs, centre_rows, ids);
  } catch (const std::invalid_argument& e) {
    FailFaiss(std::string("ApproximateIndex: the IVF index does not fit its references: ") +
              e.what());
  }
}

// A FAISS index over the references; binary IVF scanned through its cells (IvfCells).
class FaissEngineIndex final : public EngineIndex {
 public:
  FaissEngineIndex(const cv::Mat& references, const ApproximateOptions& options, bool hnsw,
                   const SavedIndex& saved)
      : refs_(references),
        faiss_(saved.empty() ? BuildFaiss(options, refs_, hnsw)
                             : ReadFaiss(options, refs_, hnsw, saved)),
        cells_(CellsOf(*faiss_, refs_)) {}

  CandidateLists Search(const cv::Mat& queries, const ApproximateOptions& options) const override {
    const int knn = std::min(options.k, refs_.rows);
    if (cells_) return SearchIvfCells(*cells_, queries, knn, options.nprobe, options.threads);
    CandidateLists out(static_cast<size_t>(queries.rows));
    // FAISS spreads the queries over its OpenMP threads itself; only the exact distances are
    // recomputed here, over OpenABLE's.
    std::vector<std::int64_t> labels(static_cast<size_t>(queries.rows) * static_cast<size_t>(knn));
    faiss_->Search(queries.data, queries.rows, knn, labels.data());
    ParallelBlocks(queries.rows, kQueryBlock, options.threads, [&](int q0, int q1) {
      for (int q = q0; q < q1; ++q) {
        std::vector<Candidate>& list = out[static_cast<size_t>(q)];
        for (int i = 0; i < knn; ++i) {
          const std::int64_t r =
              labels[static_cast<size_t>(q) * static_cast<size_t>(knn) + static_cast<size_t>(i)];
          if (r < 0 || r >= refs_.rows) continue;
          const int row = static_cast<int>(r);
          list.push_back(Candidate{row, RowDistance(refs_, row, queries, q)});
        }
        SortCandidates(list);
      }
    });
    return out;
  }

  void SetSearchBudget(const ApproximateOptions& options) override {
    faiss_->SetSearch(std::max(options.ef_search, options.k), options.nprobe);
  }

  std::vector<std::uint8_t> Serialize() const override { return faiss_->Serialize(); }

 private:
  cv::Mat refs_;  // a header of ApproximateIndex's rows, for the exact distances
  std::unique_ptr<FaissIndex> faiss_;
  std::unique_ptr<IvfCells> cells_;  // binary IVF: see IvfCells
};

std::unique_ptr<EngineIndex> BuildHnsw(const cv::Mat& references, const ApproximateOptions& options,
                                       const SavedIndex& saved) {
  return std::make_unique<FaissEngineIndex>(references, options, /*hnsw=*/true, saved);
}

std::unique_ptr<EngineIndex> BuildIvf(const cv::Mat& references, const ApproximateOptions& options,
                                      const SavedIndex& saved) {
  return std::make_unique<FaissEngineIndex>(references, options, /*hnsw=*/false, saved);
}

// FAISS keeps its own copy of the rows; HNSW adds its links, 2 M 4-byte ids per row on the
// bottom layer and about M more above.
std::int64_t HnswBytesPerRow(const ApproximateOptions& options, int /*depth*/,
                             std::int64_t row_bytes) {
  return row_bytes + 3 * options.hnsw_m * 4 + 8;
}

// FAISS keeps its own copy of the rows and an 8-byte id per row; binary IVF also the rows
// again, packed by cell for OpenABLE's scan, with a 4-byte id each (the centroids are few).
std::int64_t IvfBytesPerRow(const ApproximateOptions& /*options*/, int depth,
                            std::int64_t row_bytes) {
  return row_bytes + (depth == CV_8U ? 8 + row_bytes + 4 : 8);
}

}  // namespace

const ApproximateEngineEntry kHnswEngine = {
    "hnsw",                 // name
    "FAISS's HNSW graphs",  // summary
    /*needs_faiss=*/true,
    /*binary_only=*/false,
    /*owns_rows=*/false,
    &BuildHnsw,
    &HnswBytesPerRow,
};

const ApproximateEngineEntry kIvfEngine = {
    "ivf",                                     // name
    "FAISS's inverted files (k-means cells)",  // summary
    /*needs_faiss=*/true,
    /*binary_only=*/false,
    /*owns_rows=*/false,
    &BuildIvf,
    &IvfBytesPerRow,
};

}  // namespace openable
