// The engine flann (matching/search/engine_registry.h): OpenCV's FLANN, LSH for binary rows
// (Hamming) and randomised k-d trees for float rows (L2). M. Muja and D. G. Lowe, "Scalable
// Nearest Neighbor Algorithms for High Dimensional Data", IEEE T-PAMI 36(11), 2014 (k-d trees,
// best-bin-first within `checks` leaves); Q. Lv et al., "Multi-Probe LSH", VLDB 2007.
// OpenCV's copy (cvflann), not Debian's libflann, which seeds from std::random_device and
// cannot be made deterministic; OpenCV's draws from cv::theRNG(), seeded with
// ApproximateOptions::seed and restored afterwards. Not serialised: rebuilt from the rows.
#pragma once

#include "matching/search/approximate_engine.h"

namespace openable {

extern const ApproximateEngineEntry kFlannEngine;

}  // namespace openable
