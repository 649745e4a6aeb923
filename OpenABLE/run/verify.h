// Geometric verification and temporal consistency of a run's best matches
// (OpenABLE/verification/verification.h): for each query of the evaluated block, its
// Verification_candidates best candidates at distinct places are taken from the finished matrix
// (after sequences and the match score) or from the kept matches of the bounded mode; the
// frames of those candidates are read again, their features computed once and kept in a cache
// bounded by Verification_cache, and each candidate checked. docs/verification.md.
#pragma once

#include <string>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/run/evaluate.h"
#include "OpenABLE/run/result.h"
#include "OpenABLE/verification/verification.h"
#include "config/config.h"

namespace openable {

struct RunVerification {
  VerificationOptions options;  // as used (tolerance = Tolerance)
  std::string geometry;         // "fundamental matrix (uncalibrated)" or "essential matrix (...)"
  // Queries of the block that have candidates, in frame order; query and reference numbers
  // count from the start of their traversal, as in Matches_name.
  std::vector<QueryVerification> queries;
  int frames = 0;                 // distinct frames whose features were computed
  int extractions = 0;            // feature computations (more than frames when the cache was full)
  int pairs = 0;                  // candidates checked
  int geometric = 0;              // of those, geometrically verified
  int answered = 0;               // queries with an accepted candidate (their answer)
  double seconds = 0;             // wall time of the whole step
  std::vector<float> extract_ms;  // per feature computation (reading the frame included)
  std::vector<float> pair_ms;     // per candidate: matching and RANSAC
};

// The checks of verification that come before any frame is described: the options, a way to
// read the frames again (image folders or stereo pairs: not videos), the calibration and its
// fit to the first frame (`first_frame` of `size`), the consistency against the `queries` of
// the run. Throws InputError naming the key.
void CheckVerification(const Config& config, bool from_video, int queries,
                       const std::string& first_frame, const cv::Size& size);

// The candidates of every query of `result` (dense matrix, or kept matches when bounded),
// before verification (checks empty).
std::vector<QueryVerification> VerificationCandidates(const Config& config,
                                                      const RunResult& result);

// Verifies the candidates of `result`. Throws InputError naming a frame that cannot be read.
RunVerification VerifyRun(const Config& config, const RunResult& result,
                          ProgressReporter& progress);

// Mean and 99th percentile (nearest rank) of latencies in ms; zeros when empty.
struct LatencySummary {
  double mean = 0, p99 = 0;
};
LatencySummary Summarize(const std::vector<float>& milliseconds);

// The loops file (Loops_name): CSV "query,reference,rank,distance,score,matches,inliers,model,
// geometric,streak,verified", one line per candidate checked (docs/output_formats.md).
std::string EncodeLoops(const RunVerification& verification);

// The answers of a verification for the evaluation of `layout`: each query's accepted
// candidates, best first, and the cells of the rejected ones.
VerifiedAnswers AnswersOf(const RunVerification& verification, const EvaluationLayout& layout);

}  // namespace openable
