// The binary_ivf engine (matching/search/engine_registry.h): an inverted file over binary rows
// built without FAISS. The cell centres are trained by k-majority (k-means for Hamming space:
// each centre takes, bit by bit, the majority of its rows) on a sample of the rows, and every
// row is put in the cell of its nearest centre, all with OpenABLE's Hamming kernels
// (matching/distances.h); the search is IvfCells's (matching/search/ivf_cells.h), the same as
// the ivf engine's. FAISS's IVF trains on the rows turned into floats (256 floats a row for LDB
// 256 bits) by float k-means, whose cost made a map of ten million rows take about twenty
// minutes; counting differing bits is the distance the cells are searched by anyway.
//
// Settings (ApproximateOptions): ivf_lists cells (0: 2 sqrt(rows), at most rows / 39, as the
// ivf engine), nprobe cells searched, seed of the sample and of the first centres. The
// training: 8 rounds on a sample of 32 rows a cell (at least 65,536 rows, at most all).
// Deterministic for given rows and settings, whatever the thread count. Saved (Serialize) as
// the centres, the cells' row numbers and their rows packed for the kernels, about 4 bytes a
// row more than the rows themselves, in 8-byte aligned sections: a memory-mapped map file's
// index is searched where it lies (SavedIndex::owner), with no training and no copy. Memory:
// the rows again, packed by cell for the kernels, and a 4-byte row number each.
#pragma once

#include "matching/search/approximate_engine.h"

namespace openable {

extern const ApproximateEngineEntry kBinaryIvfEngine;

}  // namespace openable
