#include "matching/agreement.h"

#include <cstdlib>
#include <stdexcept>

namespace openable {
namespace {

// The last frame of query q's window of frames (see agreement.h).
int WindowEnd(int q, const AgreementOptions& o) {
  const int L = o.sequence_length;
  return o.partial == SequencePartial::kAhead && q < L - 1 ? L - 1 : q;
}

int WindowStart(int q, const AgreementOptions& o) {
  const int start = WindowEnd(q, o) - o.sequence_length + 1;
  return start > 0 ? start : 0;
}

int BackPartner(int q, const AgreementOptions& o) {
  const int p = q - o.Gap();
  if (p < 0) return -1;
  // Windows end no later as the query goes back, so the nearest candidate decides.
  return WindowEnd(p, o) < WindowStart(q, o) ? p : -1;
}

int ForwardPartner(int q, int queries, const AgreementOptions& o) {
  int p = q + o.Gap();
  const int after = WindowEnd(q, o) + o.sequence_length;  // first p whose window starts later
  if (p < after) p = after;
  return p < queries ? p : -1;
}

// Answers a of query qa and b of query qb (qa < qb) advance as the queries do.
bool Agree(int qa, int a, int qb, int b, const AgreementOptions& o) {
  if (a < 0 || b < 0) return false;
  const int steps = qb - qa, moved = b - a, tolerance = o.Tolerance();
  const bool forward = std::abs(moved - steps) <= tolerance;
  const bool reverse = std::abs(moved + steps) <= tolerance;
  switch (o.direction) {
    case SequenceDirection::kForward:
      return forward;
    case SequenceDirection::kReverse:
      return reverse;
    case SequenceDirection::kBoth:
      break;
  }
  return forward || reverse;
}

}  // namespace

bool AnswersAgree(int qa, int a, int qb, int b, const AgreementOptions& options) {
  return Agree(qa, a, qb, b, options);
}

int AgreementPartner(int q, int queries, const AgreementOptions& options) {
  const int back = BackPartner(q, options);
  return back >= 0 ? back : ForwardPartner(q, queries, options);
}

std::vector<std::uint8_t> AgreeingAnswers(const std::vector<int>& best,
                                          const AgreementOptions& options) {
  if (options.sequence_length < 1 || options.partners < 1)
    throw std::logic_error("AgreeingAnswers: sequence_length and partners must be >= 1");
  const int n = static_cast<int>(best.size());
  std::vector<std::uint8_t> out(best.size(), 0);
  for (int q = 0; q < n; ++q) {
    if (best[q] < 0) continue;
    // A chain of partners, each agreeing with the one before: back as far as it goes, then
    // forward from q.
    int found = 0;
    bool agree = true;
    for (int from = q, p = BackPartner(q, options); agree && found < options.partners && p >= 0;
         from = p, p = BackPartner(p, options)) {
      agree = Agree(p, best[p], from, best[from], options);
      found += agree ? 1 : 0;
    }
    for (int from = q, p = ForwardPartner(q, n, options);
         agree && found < options.partners && p >= 0; from = p, p = ForwardPartner(p, n, options)) {
      agree = Agree(from, best[from], p, best[p], options);
      found += agree ? 1 : 0;
    }
    out[q] = agree && found == options.partners ? 1 : 0;
  }
  return out;
}

}  // namespace openable
