// The engines hnsw and ivf (matching/search/engine_registry.h), FAISS's indexes built in the
// run-time module libopenable_faiss.so (matching/search/faiss_index.h, faiss_module.cc):
//
//  - hnsw: hierarchical navigable small-world graphs, IndexBinaryHNSW (Hamming) and
//    IndexHNSWFlat (L2). Y. A. Malkov and D. A. Yashunin, "Efficient and robust approximate
//    nearest neighbor search using Hierarchical Navigable Small World graphs", IEEE T-PAMI
//    42(4), 2020. Rows are added on one thread and levels drawn from FAISS's fixed seed, so the
//    graph is deterministic.
//  - ivf: inverted files, IndexBinaryIVF (Hamming) and IndexIVFFlat (L2): k-means cells,
//    `nprobe` nearest cells scanned exhaustively (binary cells by OpenABLE's Hamming kernels,
//    faiss_engines.cc). J. Sivic and A. Zisserman, "Video Google", ICCV 2003; J. Johnson,
//    M. Douze and H. Jegou, "Billion-scale similarity search with GPUs", IEEE T-BD 7(3), 2021
//    (FAISS). The k-means is seeded with the low 31 bits of ApproximateOptions::seed.
//
// Both serialise their structure (FAISS's write_index), which a saved map reads back.
#pragma once

#include "matching/search/approximate_engine.h"

namespace openable {

extern const ApproximateEngineEntry kHnswEngine;
extern const ApproximateEngineEntry kIvfEngine;

}  // namespace openable
