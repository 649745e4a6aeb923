// The entry points of the run-time module libopenable_faiss.so (matching/search/faiss_module.cc),
// the FAISS indexes of the engines hnsw and ivf (matching/search/faiss_engines.h). The module links
// FAISS, OpenMP and BLAS and nothing of OpenABLE but this header, so that openable_matching reaches
// it through ModuleSymbol (OpenABLE/base/module_loader.h) alone. Module and program come from the
// same build, so C++ types and exceptions cross the boundary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace openable {

// What the module needs of an index: a plain view of ApproximateOptions and of the rows, made
// in one place (SettingsOf, matching/search/faiss_engines.cc) with every field set from them; no
// defaults of its own, the settings' defaults and ranges are ApproximateOptions'.
struct FaissSettings {
  bool hnsw;                 // HNSW, else IVF
  bool binary;               // Hamming on packed bits (IndexBinary*), else L2 on floats
  int width;                 // bytes of a binary row, floats of a float row
  int hnsw_m;                // ApproximateOptions::hnsw_m
  int hnsw_ef_construction;  // ApproximateOptions::hnsw_ef_construction
  int ef_search;             // ApproximateOptions::ef_search, raised to k
  int ivf_lists;             // ApproximateOptions::ivf_lists (0: automatic)
  int nprobe;                // ApproximateOptions::nprobe
  int threads;               // OpenMP threads of training and searches (0: all cores)
  int seed;                  // IVF k-means seed: the low 31 bits of ApproximateOptions::seed
};

// One built FAISS index.
class FaissIndex {
 public:
  virtual ~FaissIndex() = default;
  // `labels` (n x k): the rows of the k approximate nearest references of each of the n
  // queries (rows of the index's type and width, continuous), -1 where fewer were found.
  // Reads the index only.
  virtual void Search(const void* queries, int n, int k, std::int64_t* labels) const = 0;
  // Sets ef_search (HNSW) or nprobe (IVF, capped at the cells) for later searches; not while
  // a search runs.
  virtual void SetSearch(int ef_search, int nprobe) = 0;
  // The index in FAISS's serialisation (write_index / write_index_binary).
  virtual std::vector<std::uint8_t> Serialize() const = 0;
  // Rows in the index (FAISS's ntotal).
  virtual std::int64_t Size() const = 0;
  // A binary IVF index over a flat quantizer: its cells' centres (one row of the index's width
  // per cell, cell after cell) and the rows of each cell, in FAISS's order; true. False for
  // any other index, leaving both untouched.
  virtual bool BinaryCells(std::vector<std::uint8_t>* centres,
                           std::vector<std::vector<std::int64_t>>* cells) const = 0;
};

}  // namespace openable

// Builds the index of `settings` over `rows` (n rows, continuous). Throws std::runtime_error
// with FAISS's message on failure.
extern "C" openable::FaissIndex* openable_faiss_build(const openable::FaissSettings& settings,
                                                      const void* rows, int n);
using OpenableFaissBuild = openable::FaissIndex* (*)(const openable::FaissSettings&, const void*,
                                                     int);
// Reads an index written by FaissIndex::Serialize; `settings` gives the search parameters and
// threads (the structure comes from the bytes). Throws std::runtime_error on bytes that FAISS
// cannot read or that hold another kind of index.
extern "C" openable::FaissIndex* openable_faiss_read(const openable::FaissSettings& settings,
                                                     const std::uint8_t* bytes, std::size_t size);
using OpenableFaissRead = openable::FaissIndex* (*)(const openable::FaissSettings&,
                                                    const std::uint8_t*, std::size_t);
