// The cells of an inverted file over binary rows, scanned with OpenABLE's Hamming kernels
// (matching/distances.h): the cell centres, and each cell's rows packed for the kernel with
// their row numbers. Shared by the IVF engines (FAISS's cells, matching/search/faiss_engines.cc,
// and the cells trained here, matching/search/binary_ivf.h), whose searches are the same: the
// nprobe cells whose centres are nearest the query (ties: the lower cell), then the k nearest
// of their rows by exact Hamming distance (ties: the lower row).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "matching/distances.h"
#include "matching/search/approximate.h"

namespace openable {

// Cells of an inverted file over `rows` rows: `requested` when given (> 0, at most the rows),
// else 2 sqrt(rows), capped so that every cell has FAISS's minimum of 39 training rows. The
// rule of both IVF engines, so that they compare at equal sizes.
inline int IvfCellCount(int requested, int rows) {
  if (requested > 0) return std::min(requested, rows);
  const int cells = static_cast<int>(std::lround(2.0 * std::sqrt(static_cast<double>(rows))));
  return std::max(1, std::min(cells, rows / 39));
}

// Cell c holds the rows ids[offsets[c]] .. ids[offsets[c + 1] - 1] of the references, in
// that order, packed for the kernel in rows[c] (null when the cell is empty). `ids` points
// into `owned_ids`, or into bytes that `owner` keeps alive (an index read in place from a
// mapped map file), as the packed rows may.
struct IvfCells {
  std::unique_ptr<HammingReferences> centres;            // one row per cell
  std::vector<std::unique_ptr<HammingReferences>> rows;  // each cell's rows (null: empty)
  std::vector<std::uint32_t> offsets;                    // cells + 1, from 0 to the rows
  const std::int32_t* ids = nullptr;
  std::vector<std::int32_t> owned_ids;
  std::shared_ptr<const void> owner;
  int Cells() const { return static_cast<int>(rows.size()); }
  int Count(int c) const {
    return static_cast<int>(offsets[static_cast<std::size_t>(c) + 1] -
                            offsets[static_cast<std::size_t>(c)]);
  }
  const std::int32_t* Ids(int c) const { return ids + offsets[static_cast<std::size_t>(c)]; }
};

// The cells of `centres` (one CV_8U row per cell, the references' width) holding the rows
// `cells[c]` of `references` (every row exactly once). Throws std::invalid_argument naming
// the defect (a row out of range, rows missing or twice, another width): a saved index
// that does not describe these references.
std::unique_ptr<IvfCells> MakeIvfCells(const cv::Mat& references, const cv::Mat& centres,
                                       const std::vector<std::vector<int>>& cells);

// Up to k candidates for each row of `queries` from the `nprobe` nearest cells, sorted as
// CandidateLists says, the queries spread over `threads` threads (0: all cores).
CandidateLists SearchIvfCells(const IvfCells& cells, const cv::Mat& queries, int k, int nprobe,
                              int threads);

}  // namespace openable
