// Module libopenable_faiss.so (matching/search/faiss_index.h): the HNSW and IVF indexes of FAISS
// for ApproximateIndex. FAISS brings libgomp, BLAS and LAPACK, which a run that does not use it no
// longer loads at start-up.
#include <faiss/IndexBinaryFlat.h>
#include <faiss/IndexBinaryHNSW.h>
#include <faiss/IndexBinaryIVF.h>
#include <faiss/IndexFlat.h>
#include <faiss/IndexHNSW.h>
#include <faiss/IndexIVFFlat.h>
#include <faiss/impl/FaissException.h>
#include <faiss/impl/io.h>
#include <faiss/index_io.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "matching/search/faiss_index.h"
#include "matching/search/ivf_cells.h"

namespace openable {
namespace {

// OpenMP threads of the calling thread for one FAISS call (omp_set_num_threads sets the
// calling thread's own setting, so concurrent callers do not disturb each other), restored
// afterwards.
class OmpThreads {
 public:
  explicit OmpThreads(int threads) : saved_(omp_get_max_threads()) {
    omp_set_num_threads(threads > 0 ? threads : omp_get_num_procs());
  }
  ~OmpThreads() { omp_set_num_threads(saved_); }
  OmpThreads(const OmpThreads&) = delete;
  OmpThreads& operator=(const OmpThreads&) = delete;

 private:
  int saved_;
};

// k-means of the IVF cells: seeded, 10 iterations (FAISS's IVF default) on at most 64 rows
// a cell (a sample drawn with the seed), so that training stays a small part of the build.
void SetClustering(faiss::ClusteringParameters& cp, int seed) {
  cp.seed = seed;
  cp.niter = 10;
  cp.max_points_per_centroid = 64;
}

// The search parameters (ef_search of HNSW, nprobe of IVF) on a built or read index; false when
// the index is not of the kind `hnsw` names (Hnsw or Ivf: the binary or float classes of
// FAISS).
template <typename Hnsw, typename Ivf, typename Base>
bool SetSearchAs(Base* index, bool hnsw, int ef_search, int nprobe) {
  if (auto* h = dynamic_cast<Hnsw*>(index); h && hnsw) {
    h->hnsw.efSearch = ef_search;
    return true;
  }
  if (auto* v = dynamic_cast<Ivf*>(index); v && !hnsw) {
    v->nprobe = std::min<std::size_t>(static_cast<size_t>(nprobe), v->nlist);
    return true;
  }
  return false;
}
bool SetSearch(faiss::IndexBinary* index, bool hnsw, int ef_search, int nprobe) {
  return SetSearchAs<faiss::IndexBinaryHNSW, faiss::IndexBinaryIVF>(index, hnsw, ef_search, nprobe);
}
bool SetSearch(faiss::Index* index, bool hnsw, int ef_search, int nprobe) {
  return SetSearchAs<faiss::IndexHNSWFlat, faiss::IndexIVFFlat>(index, hnsw, ef_search, nprobe);
}
template <typename Base>
bool SetSearch(Base* index, const FaissSettings& s) {
  return SetSearch(index, s.hnsw, s.ef_search, s.nprobe);
}

bool IsHnsw(const faiss::IndexBinary* index) {
  return dynamic_cast<const faiss::IndexBinaryHNSW*>(index) != nullptr;
}
bool IsHnsw(const faiss::Index* index) {
  return dynamic_cast<const faiss::IndexHNSWFlat*>(index) != nullptr;
}
void Write(const faiss::IndexBinary* index, faiss::IOWriter* writer) {
  faiss::write_index_binary(index, writer);
}
void Write(const faiss::Index* index, faiss::IOWriter* writer) {
  faiss::write_index(index, writer);
}

bool CellsOf(const faiss::IndexBinary* index, std::vector<std::uint8_t>* centres,
             std::vector<std::vector<std::int64_t>>* cells) {
  const auto* ivf = dynamic_cast<const faiss::IndexBinaryIVF*>(index);
  if (ivf == nullptr) return false;
  const auto* flat = dynamic_cast<const faiss::IndexBinaryFlat*>(ivf->quantizer);
  if (flat == nullptr || flat->ntotal != static_cast<faiss::Index::idx_t>(ivf->nlist)) return false;
  *centres = flat->xb;
  cells->assign(ivf->nlist, {});
  for (std::size_t l = 0; l < ivf->nlist; ++l) {
    const std::size_t n = ivf->invlists->list_size(l);
    faiss::InvertedLists::ScopedIds ids(ivf->invlists, l);
    (*cells)[l].assign(ids.get(), ids.get() + n);
  }
  return true;
}
bool CellsOf(const faiss::Index*, std::vector<std::uint8_t>*,
             std::vector<std::vector<std::int64_t>>*) {
  return false;
}

// A binary (faiss::IndexBinary: uint8_t rows, int32_t distances) or float (faiss::Index)
// index.
template <typename BaseIndex, typename Element, typename Distance>
class Wrapped final : public FaissIndex {
 public:
  using Base = BaseIndex;
  Wrapped(std::unique_ptr<BaseIndex> index, int threads)
      : index_(std::move(index)), threads_(threads) {}
  void Search(const void* queries, int n, int k, std::int64_t* labels) const override {
    std::vector<Distance> distances(static_cast<size_t>(n) * static_cast<size_t>(k));
    const OmpThreads omp(std::min(std::max(1, n), threads_ > 0 ? threads_ : omp_get_num_procs()));
    index_->search(n, static_cast<const Element*>(queries), k, distances.data(), labels);
  }
  void SetSearch(int ef_search, int nprobe) override {
    openable::SetSearch(index_.get(), IsHnsw(index_.get()), ef_search, nprobe);
  }
  std::vector<std::uint8_t> Serialize() const override {
    faiss::VectorIOWriter writer;
    Write(index_.get(), &writer);
    return std::move(writer.data);
  }
  std::int64_t Size() const override { return index_->ntotal; }
  bool BinaryCells(std::vector<std::uint8_t>* centres,
                   std::vector<std::vector<std::int64_t>>* cells) const override {
    return CellsOf(index_.get(), centres, cells);
  }

 private:
  std::unique_ptr<BaseIndex> index_;
  int threads_;
};
using BinaryIndex = Wrapped<faiss::IndexBinary, std::uint8_t, std::int32_t>;
using FloatIndex = Wrapped<faiss::Index, float, float>;

// Builds an index of `d` dimensions (bits or floats) over n rows `x`: Hnsw or an Ivf over a Flat
// quantizer, FAISS's binary or float classes, wrapped in Wrapper.
template <typename Wrapper, typename Hnsw, typename Ivf, typename Flat, typename Element>
FaissIndex* BuildAs(const FaissSettings& s, int d, const Element* x, int n) {
  std::unique_ptr<typename Wrapper::Base> index;
  if (s.hnsw) {
    auto h = std::make_unique<Hnsw>(d, s.hnsw_m);
    h->hnsw.efConstruction = s.hnsw_ef_construction;
    // One thread: HNSW inserts the rows of a level in parallel, in an order that depends on
    // the threads' timing, and the graph (so the candidates) with it.
    const OmpThreads omp(1);
    h->add(n, x);
    index = std::move(h);
  } else {
    auto v =
        std::make_unique<Ivf>(new Flat(d), d, static_cast<size_t>(IvfCellCount(s.ivf_lists, n)));
    v->own_fields = true;
    SetClustering(v->cp, s.seed);
    const OmpThreads omp(s.threads);
    v->train(n, x);
    v->add(n, x);
    index = std::move(v);
  }
  SetSearch(index.get(), s);
  return new Wrapper(std::move(index), s.threads);
}

FaissIndex* Build(const FaissSettings& s, const void* rows, int n) {
  if (s.binary)
    return BuildAs<BinaryIndex, faiss::IndexBinaryHNSW, faiss::IndexBinaryIVF,
                   faiss::IndexBinaryFlat>(s, 8 * s.width, static_cast<const std::uint8_t*>(rows),
                                           n);
  return BuildAs<FloatIndex, faiss::IndexHNSWFlat, faiss::IndexIVFFlat, faiss::IndexFlatL2>(
      s, s.width, static_cast<const float*>(rows), n);
}

FaissIndex* Read(const FaissSettings& s, const std::uint8_t* bytes, std::size_t size) {
  faiss::VectorIOReader reader;
  reader.data.assign(bytes, bytes + size);
  const char* kind = s.hnsw ? "HNSW" : "IVF";
  if (s.binary) {
    std::unique_ptr<faiss::IndexBinary> index(faiss::read_index_binary(&reader));
    if (!SetSearch(index.get(), s) || index->d != 8 * s.width)
      throw std::runtime_error(std::string("the bytes hold another index than a binary ") + kind +
                               " index of " + std::to_string(8 * s.width) + " bits");
    return new BinaryIndex(std::move(index), s.threads);
  }
  std::unique_ptr<faiss::Index> index(faiss::read_index(&reader));
  if (!SetSearch(index.get(), s) || index->d != s.width)
    throw std::runtime_error(std::string("the bytes hold another index than a float ") + kind +
                             " index of " + std::to_string(s.width) + " floats");
  return new FloatIndex(std::move(index), s.threads);
}

}  // namespace
}  // namespace openable

// FAISS's exceptions are turned into std::runtime_error here: the program does not see FAISS's
// headers.
extern "C" openable::FaissIndex* openable_faiss_build(const openable::FaissSettings& settings,
                                                      const void* rows, int n) {
  try {
    return openable::Build(settings, rows, n);
  } catch (const faiss::FaissException& e) {
    throw std::runtime_error(std::string("FAISS: ") + e.what());
  }
}

extern "C" openable::FaissIndex* openable_faiss_read(const openable::FaissSettings& settings,
                                                     const std::uint8_t* bytes, std::size_t size) {
  try {
    return openable::Read(settings, bytes, size);
  } catch (const faiss::FaissException& e) {
    throw std::runtime_error(std::string("FAISS: ") + e.what());
  }
}
