// The engines hnsw and ivf (matching/search/engine_registry.h), FAISS's indexes built in the
// run-time module libopenable_faiss.so (faiss_index.h, faiss_module.cc); both serialise their
// structure (write_index), which a saved map reads back.
//  - hnsw: IndexBinaryHNSW (Hamming), IndexHNSWFlat (L2); Y. A. Malkov and D. A. Yashunin,
//    IEEE T-PAMI 42(4), 2020. Rows added on one thread, FAISS's fixed seed: a deterministic graph.
//  - ivf: IndexBinaryIVF (Hamming), IndexIVFFlat (L2): k-means cells seeded with the low 31 bits
//    of ApproximateOptions::seed, `nprobe` cells scanned (binary cells by OpenABLE's kernels).
//    J. Sivic and A. Zisserman, "Video Google", ICCV 2003; J. Johnson, M. Douze and H. Jegou,
//    "Billion-scale similarity search with GPUs", IEEE T-BD 7(3), 2021 (FAISS).
#pragma once

#include "matching/search/approximate_engine.h"

namespace openable {

extern const ApproximateEngineEntry kHnswEngine;
extern const ApproximateEngineEntry kIvfEngine;

}  // namespace openable
