// The engine flann (matching/search/engine_registry.h): OpenCV's FLANN, LSH for binary rows
// (Hamming) and randomised k-d trees for float rows (L2).
//
// Papers: M. Muja and D. G. Lowe, "Scalable Nearest Neighbor Algorithms for High Dimensional
// Data", IEEE T-PAMI 36(11), 2014 (randomised k-d trees, best-bin-first with a budget of
// `checks` leaves); Q. Lv et al., "Multi-Probe LSH", VLDB 2007 (LSH tables probed at
// neighbouring keys), as FLANN implements them.
//
// The FLANN used is OpenCV's copy (module opencv_flann, namespace cvflann), not Debian's
// libflann 1.9.2: that build seeds its LSH bit selection and its k-d tree shuffles from
// std::random_device, so two runs on the same data give different candidates, and it cannot
// be made deterministic; OpenCV's copy draws from cv::theRNG() of the calling thread, which
// the build seeds with ApproximateOptions::seed and restores afterwards. The index is not
// serialised: it is built again from the rows (milliseconds to seconds).
#pragma once

#include "matching/search/approximate_engine.h"

namespace openable {

extern const ApproximateEngineEntry kFlannEngine;

}  // namespace openable
