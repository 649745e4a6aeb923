// How confident a best match is: the match score (the key Match_score), through which every
// place that ranks or accepts matches (evaluation, the bounded mode's matches file, the online
// detector) scores a query's candidates. distance: the candidate's own distance, as ABLE does.
// ratio: Lowe's ratio test, as SeqSLAM uses it: the distance over the smallest of the query's
// other candidates outside +-`window` frames (the frames next to a match show the same place);
// no such rival, or one at distance 0, gives 1; non-finite distances are never candidates nor
// rivals. docs/evaluation.md, "The match score".
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/enum_names.h"

namespace openable {

enum class MatchScore { kDistance, kRatio };
OPENABLE_ENUM_NAMES(MatchScore, "distance", "ratio")

// The score of best matches (Match_score) and the window of its rivals (Match_score_window):
// the one struct of these settings, held by every option struct that scores matches (the run's
// MatchingOptions, the bounded mode's KeepRules, the evaluation, the criteria without ground
// truth, the online detector, the report) and copied whole between them.
struct MatchScoreOptions {
  MatchScore kind = MatchScore::kDistance;
  int window = 10;  // frames, 0..100000

  // Throws InputError naming Match_score_window when the window is out of range.
  void Check() const;
  // Throws InputError naming Match_score_window when, with the ratio, the window leaves no
  // rival among `references` frames; `where` names them in the message (may be empty).
  void CheckRivals(int references, const std::string& where) const;
};

// The score of candidate `best` of a row of `count` candidate distances (columns 0 .. count-1
// are the candidates, column = frame of the reference traversal).
float ScoreOfCandidate(const float* distances, int count, int best, const MatchScoreOptions& score);

// The same over sparse candidates: (distance, frame) pairs of one query (any order; an
// approximate search's candidates), candidate `best` an index into `candidates`. Rivals are the
// other candidates given; a rival the search did not return cannot count.
float ScoreOfCandidate(const std::vector<std::pair<float, int>>& candidates, std::size_t best,
                       const MatchScoreOptions& score);

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
