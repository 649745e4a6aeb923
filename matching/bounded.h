// Memory-bounded matching (Matrix_mode 2, or auto when the dense matrix would not fit): the
// matrix is never held. Each thread takes ranges of query rows and computes, row by row, the
// distances, the sequence sums over a ring of the last rows and the row's kept matches (the
// Best_matches smallest of each query, and the band |i - j| <= Band_width), in memory that does
// not grow with the number of queries. Rows and columns as the evaluation's (one traversal:
// candidates at least Exclusion frames earlier); Eq. 5 divides by the largest distance computed.
// Where every cell is computed, the matches equal MatchesFromMatrix's on the dense matrix.
// docs/matching.md, "Dense and bounded modes".
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "matching/agreement.h"
#include "matching/distances.h"
#include "matching/score.h"
#include "matching/search/approximate.h"
#include "matching/sequence.h"

namespace openable {

struct Match {
  int query = 0;       // frame number in the query traversal
  int reference = 0;   // frame number in the reference traversal
  float distance = 0;  // normalised (M')
  int rank = 0;        // 1 = best of its query, ..., k; 0 = kept by the band only
  float score = 0;     // KeepRules::score of this match (matching/score.h): the normalised
                       // distance, or its ratio to the best rival outside the window
};

struct KeepRules {
  int best = 10;        // k (Best_matches), 0..100000
  int band = -1;        // |i - j| <= band (Band_width); -1 none
  int exclusion = 100;  // one traversal: candidates at least this many frames earlier, >= 1
  bool one_traversal = true;
  MatchScoreOptions score;  // the score of each kept match (Match_score, Match_score_window)

  // Throws InputError naming the key (Best_matches, Band_width, Exclusion) of a bad value.
  void Check() const;
};

// Which rows and columns of the concatenated descriptors are matched.
struct MatchBlock {
  int query_first = 0, query_count = 0;          // rows of the queries
  int reference_first = 0, reference_count = 0;  // rows of the references
  bool one_traversal = true;
};

// The block of a run whose traversals start at `starts` (1 or 2 traversals) over `n` frames.
MatchBlock BlockOf(const std::vector<int>& starts, int n);

// The kept matches of one row of (unnormalised) distances `s` of query q; appended to `out`.
// Non-finite cells (skipped sequence cells) are never kept. Scores are ratios, or the raw
// distance with MatchScore::kDistance (the callers set it to the normalised distance).
void KeepRow(const float* s, int references, int q, const KeepRules& rules,
             std::vector<Match>& out);

// The matches kept from a dense normalised matrix (rows and columns of the whole run).
std::vector<Match> MatchesFromMatrix(const cv::Mat1f& normalized, const MatchBlock& block,
                                     const KeepRules& rules);

// Per query 0 .. queries - 1, whether its best match (the match of rank 1 in `matches`, which
// may hold others) is accepted: its score is <= `threshold` and, when `consistency` is given,
// the best matches of consistency->partners independent queries agree with it
// (matching/agreement.h; a query without a best match is never accepted nor a partner).
std::vector<std::uint8_t> AcceptedMatches(const std::vector<Match>& matches, int queries,
                                          double threshold,
                                          const AgreementOptions* consistency = nullptr);

struct BoundedOptions {
  // The metric of the descriptor rows; none: by their type (Hamming for CV_8U, L2 for CV_32F).
  std::optional<Metric> metric;
  int sequence_length = 1;
  SequenceDirection direction = SequenceDirection::kForward;
  SequencePartial partial = SequencePartial::kAhead;
  int threads = 0;
  // Query rows per range of the fused pipeline (each thread takes ranges in turn); 0 chooses
  // from the rows and threads (64 to 1024). Tests set a few rows to cross many range starts.
  int range_rows = 0;
  // BoundedMatches along diagonals (Sequence_direction 0) of Hamming or L1 rows: references
  // per column tile, each range's rows being computed tile by tile so that distances, sums and
  // the kept matches stay in cache. 0 chooses (1024 columns); -1 whole rows. Tests set a few
  // columns to cross many tile edges. A multiple of 4, at least 2 L (rounded up to that).
  int tile_columns = 0;
  // The queries computed: rows [query_begin, query_end) of the block (end -1: to the last),
  // with the sequence history read from the rows before query_begin. A distributed run gives
  // each process one share (OpenABLE/cluster/cluster.h); the matches are those the whole block
  // gives for these queries.
  int query_begin = 0, query_end = -1;
  // false: distances stay raw (unnormalised, the scores of MatchScore::kDistance too) and
  // max_distance is the largest of this share; the caller normalises with NormalizeMatches
  // once the largest distance of every share is known.
  bool normalize = true;
};

// Divides the distances by `max_distance` (Eq. 5; nothing when it is 0) and, for
// MatchScore::kDistance, sets the scores to the normalised distances.
void NormalizeMatches(std::vector<Match>& matches, float max_distance,
                      const MatchScoreOptions& score);

// Computes the block range by range from the descriptors (CV_8U: Hamming or L1 as
// options.metric says, CV_32F: L2) and keeps the matches; `max_distance` receives the Eq. 5
// divisor. progress(done rows, rows).
std::vector<Match> BoundedMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                  const KeepRules& rules, const BoundedOptions& options,
                                  float& max_distance,
                                  const std::function<void(int, int)>& progress = {});

// The same pipeline writing each row's sequence sums (unnormalised) into rows
// block.query_first + i, columns from block.reference_first, of `out` (which holds them): the
// dense matrix of the block in one pass over the descriptors, with no single-frame matrix.
// Returns the largest finite sum. Every query of the block is computed (options.query_begin,
// query_end and normalize are not used).
float SequenceMatrix(const cv::Mat& descriptors, const MatchBlock& block,
                     const BoundedOptions& options, cv::Mat1f& out,
                     const std::function<void(int, int)>& progress = {});

// Approximate_search: the index of `approximate` (its engine and search budget; its k and
// threads are set here: matching/search/approximate.h) gives Best_matches candidates per query
// (with one traversal, Best_matches + 2 x Exclusion, of which those Exclusion frames back are
// kept), each scored by its exact sequence sum; the k best by that score are kept. Normalised by
// the largest score computed.
std::vector<Match> ApproximateMatches(const cv::Mat& descriptors, const MatchBlock& block,
                                      const KeepRules& rules, const BoundedOptions& options,
                                      const ApproximateOptions& approximate, float& max_distance);

}  // namespace openable
