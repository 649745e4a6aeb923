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
#include <vector>

#include <opencv2/core.hpp>

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

struct IvfCells {
  std::unique_ptr<HammingReferences> centres;            // one row per cell
  std::vector<std::unique_ptr<HammingReferences>> rows;  // each cell's rows (null: empty)
  std::vector<std::vector<int>> ids;                     // their rows of the references
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
