// How confident a best match is: the match score (the key Match_score). Every place that ranks
// or accepts matches (the per-query evaluation, the bounded mode's matches file, the online
// detector) scores a query's candidates through these functions.
//
//  - distance: the candidate's own distance (smaller = more confident), as ABLE does.
//  - ratio: the candidate's distance divided by the smallest distance of the query's other
//    candidates outside a window of +-`window` frames around it, in the same reference
//    traversal: Lowe's ratio test, as SeqSLAM and the place-recognition literature use it. A
//    right match stands out from every other place (ratio well below 1); a wrong one often has
//    a rival elsewhere in the route as close as itself (ratio near 1). The window keeps the
//    frames next to the candidate, which show the same place, from counting as rivals.
//    Conventions: no candidate outside the window, or a rival at distance 0, gives 1 (nothing
//    to tell the match from); non-finite distances (sequence cells skipped at the start of a
//    traversal, matching/sequence.h) are never candidates nor rivals.
#pragma once

#include <limits>
#include <utility>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable {

enum class MatchScore { kDistance, kRatio };
OPENABLE_ENUM_NAMES(MatchScore, "distance", "ratio")

// The score of candidate `best` of a row of `count` candidate distances (columns 0 .. count-1
// are the candidates, column = frame of the reference traversal).
float ScoreOfCandidate(const float* distances, int count, int best, MatchScore score, int window);

// The same over sparse candidates: (distance, frame) pairs of one query (any order; an
// approximate search's candidates), candidate `best` an index into `candidates`. Rivals are the
// other candidates given; a rival the search did not return cannot count.
float ScoreOfCandidate(const std::vector<std::pair<float, int>>& candidates, std::size_t best,
                       MatchScore score, int window);

// The best candidate of a row: the smallest finite distance, the lowest column on ties; -1
// when no distance is finite.
int BestCandidate(const float* distances, int count);

// The k best candidates at distinct places, for a check that looks at several candidates of a
// query (geometric verification): candidates in increasing order of distance (ties: the lower
// frame first), each taken unless it lies within +-`window` frames of one already taken (the
// frames next to a candidate show the same place). Returns indices into `candidates`, best
// first; non-finite distances are never taken. The first is the query's best match
// (BestCandidate on a dense row).
std::vector<std::size_t> DistinctBest(const std::vector<std::pair<float, int>>& candidates, int k,
                                      int window);

}  // namespace openable
