// Whether a query's best match is confirmed by the best match of another query whose sequence
// shares no frame with it: the evidence, without ground truth, that the answer follows the route
// (a right answer's partner lands near b(q) - (q - p); unrelated best matches fall anywhere).
// The partner must be independent because consecutive queries share L - 1 of their L terms and
// move together whether right or wrong. Used alike by the criteria without ground truth
// (OpenABLE/evaluation/unsupervised.h) and by Match_consistency, so a run's accepted matches are
// the answers the criterion counted as confirmed. docs/evaluation.md, "Without ground truth".
#pragma once

#include <cstdint>
#include <vector>

#include "matching/sequence.h"

namespace openable {

struct AgreementOptions {
  int sequence_length = 1;  // L of the matrix whose answers are compared (>= 1)
  SequencePartial partial = SequencePartial::kAhead;  // the window of the first L - 1 queries
  // The step of the answers as the queries advance: +1 along diagonals, -1 along
  // anti-diagonals, either with kBoth.
  SequenceDirection direction = SequenceDirection::kForward;
  // n: partners that must agree, the nearest first: back from q as far as the traversal
  // allows, then forward (each partner's partner in turn); >= 1.
  int partners = 1;

  // Frames between a query and its partner, at least: L, and never fewer than 10, so that an
  // answer stuck on one place (the same reference for every query) cannot agree with itself
  // within the tolerance.
  int Gap() const { return sequence_length > kMinGap ? sequence_length : kMinGap; }
  // Frames of disagreement allowed: 3, or a tenth of the gap for long sequences (two
  // traversals at slightly different speeds drift apart along a long gap).
  int Tolerance() const {
    const int tenth = (Gap() + 5) / 10;
    return tenth > 3 ? tenth : 3;
  }
  static constexpr int kMinGap = 10;
};

// best[q]: the answer of query q (its best reference frame, counted from the reference
// traversal's first frame), -1 without one; q counts the frames of the query traversal from
// its first. Returns, per query, 1 when it has an answer and `options.partners` partners that
// have answers agreeing with it, else 0. Throws std::logic_error when sequence_length or
// partners is below 1.
std::vector<std::uint8_t> AgreeingAnswers(const std::vector<int>& best,
                                          const AgreementOptions& options);

// The partner of query q among `queries` queries, or -1 when there is none: the nearest
// p <= q - Gap() whose window ends before q's starts, else the nearest such p forward. Query
// q's window is frames q - L + 1 .. q (clipped at its traversal's start), or 0 .. L - 1 for
// the first L - 1 queries with kAhead.
// With queries = q + 1 (online: no later query is known) only the one back.
int AgreementPartner(int q, int queries, const AgreementOptions& options);

// Whether answer a of query qa and answer b of query qb (qa < qb) advance as the queries do:
// b - a within Tolerance() of qb - qa (of qa - qb for the reverse direction; either for
// both). False when an answer is -1.
bool AnswersAgree(int qa, int a, int qb, int b, const AgreementOptions& options);

}  // namespace openable
