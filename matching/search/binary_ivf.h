// The binary_ivf engine (matching/search/engine_registry.h): an inverted file over binary rows
// built without FAISS. Cell centres are trained by k-majority (each centre takes, bit by bit,
// the majority of its rows) with OpenABLE's Hamming kernels, where FAISS's IVF runs float
// k-means on the rows turned into floats, whose cost grows as rows^1.5; the search is
// IvfCells's, as the ivf engine's. Deterministic whatever the thread count. Saved in 8-byte
// aligned sections, so a memory-mapped map's index is searched where it lies (SavedIndex::owner).
// Settings, memory and build times: docs/matching.md, "Choosing an engine".
#pragma once

#include "matching/search/approximate_engine.h"

namespace openable {

extern const ApproximateEngineEntry kBinaryIvfEngine;

}  // namespace openable
