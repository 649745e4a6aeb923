#include "matching/agreement.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <set>

namespace openable {
namespace {

// The frames of query q's sequence, written from the rule (not from the code's formulas):
// q - L + 1 .. q clipped at 0, or 0 .. L - 1 for the first L - 1 queries with ahead.
std::set<int> Window(int q, int L, SequencePartial partial) {
  std::set<int> frames;
  const int end = partial == SequencePartial::kAhead && q < L - 1 ? L - 1 : q;
  for (int f = std::max(0, end - L + 1); f <= end; ++f) frames.insert(f);
  return frames;
}

bool Disjoint(const std::set<int>& a, const std::set<int>& b) {
  for (int x : a)
    if (b.count(x)) return false;
  return true;
}

// The partner by exhaustive search: the nearest p <= q - gap with a disjoint window, else the
// nearest p >= q + gap with a disjoint window.
int BrutePartner(int q, int n, int L, SequencePartial partial, int gap) {
  for (int p = q - gap; p >= 0; --p)
    if (Disjoint(Window(p, L, partial), Window(q, L, partial))) return p;
  for (int p = q + gap; p < n; ++p)
    if (Disjoint(Window(p, L, partial), Window(q, L, partial))) return p;
  return -1;
}

TEST(Agreement, GapAndToleranceFollowTheSequenceLength) {
  AgreementOptions o;
  o.sequence_length = 1;
  EXPECT_EQ(o.Gap(), 10);  // never fewer than 10 frames
  EXPECT_EQ(o.Tolerance(), 3);
  o.sequence_length = 40;
  EXPECT_EQ(o.Gap(), 40);
  EXPECT_EQ(o.Tolerance(), 4);
  o.sequence_length = 100;
  EXPECT_EQ(o.Tolerance(), 10);
}

// Hand-worked partners, L = 20 with ahead: query 5 has the window 0-19, so its partner is the
// first query whose window starts after 19, query 39 (window 20-39); query 25 (window 6-25) has
// no disjoint query 20 or more frames back (query 5's window is 0-19), so it takes query 45;
// query 45 takes query 25. With scale, query 25 takes query 5 (window 0-5).
TEST(Agreement, PartnersByHand) {
  AgreementOptions o;
  o.sequence_length = 20;
  o.partial = SequencePartial::kAhead;
  EXPECT_EQ(AgreementPartner(5, 80, o), 39);
  EXPECT_EQ(AgreementPartner(25, 80, o), 45);
  EXPECT_EQ(AgreementPartner(45, 80, o), 25);
  EXPECT_EQ(AgreementPartner(70, 80, o), 50);
  EXPECT_EQ(AgreementPartner(5, 30, o), -1);  // 39 is beyond the queries
  o.partial = SequencePartial::kScale;
  EXPECT_EQ(AgreementPartner(25, 80, o), 5);
  EXPECT_EQ(AgreementPartner(5, 80, o), 25);
}

TEST(Agreement, PartnersEqualTheExhaustiveSearch) {
  for (const SequencePartial partial :
       {SequencePartial::kAhead, SequencePartial::kScale, SequencePartial::kSkip})
    for (int L : {1, 2, 5, 10, 17, 40}) {
      AgreementOptions o;
      o.sequence_length = L;
      o.partial = partial;
      for (int n : {1, 15, 60, 130})
        for (int q = 0; q < n; ++q)
          ASSERT_EQ(AgreementPartner(q, n, o), BrutePartner(q, n, L, partial, o.Gap()))
              << "L " << L << " n " << n << " q " << q << " partial " << EnumName(partial);
    }
}

// Answers along the route agree; answers stuck on one place, or random, do not; a query
// without an answer, or whose partner has none, never agrees.
TEST(Agreement, RouteAnswersAgreeStuckOrRandomOnesDoNot) {
  AgreementOptions o;
  o.sequence_length = 10;
  std::vector<int> route(100), stuck(100, 37), random(100);
  std::mt19937 rng(4);
  for (int q = 0; q < 100; ++q) {
    route[q] = 200 + q;
    random[q] = static_cast<int>(rng() % 1000);
  }
  auto count = [&](const std::vector<int>& best) {
    int n = 0;
    for (std::uint8_t a : AgreeingAnswers(best, o)) n += a;
    return n;
  };
  EXPECT_EQ(count(route), 100);
  EXPECT_EQ(count(stuck), 0);
  EXPECT_LE(count(random), 5);
  // Within the tolerance (3 frames for L = 10): a route at a slightly different speed, its
  // partners 10 queries apart with scale (ahead pairs the first queries with query 19).
  o.partial = SequencePartial::kScale;
  std::vector<int> faster(100);
  for (int q = 0; q < 100; ++q) faster[q] = static_cast<int>(q * 1.25);
  EXPECT_EQ(count(faster), 100);  // 10 queries apart, 12 or 13 references apart
  std::vector<int> much_faster(100);
  for (int q = 0; q < 100; ++q) much_faster[q] = q * 2;
  EXPECT_EQ(count(much_faster), 0);  // 20 apart: 10 off
  o.partial = SequencePartial::kAhead;
  route[50] = -1;  // no answer: itself and its two partners (40, 60) lose
  const std::vector<std::uint8_t> a = AgreeingAnswers(route, o);
  EXPECT_EQ(a[50], 0);
  EXPECT_EQ(a[60], 0);
  EXPECT_EQ(a[40], 1);  // 40's partner is 30
}

TEST(Agreement, DirectionOfTheReferenceRoute) {
  AgreementOptions o;
  o.sequence_length = 5;
  std::vector<int> backwards(60);
  for (int q = 0; q < 60; ++q) backwards[q] = 500 - q;
  const auto all = [](const std::vector<std::uint8_t>& a) {
    int n = 0;
    for (std::uint8_t x : a) n += x;
    return n;
  };
  EXPECT_EQ(all(AgreeingAnswers(backwards, o)), 0);
  o.direction = SequenceDirection::kReverse;
  EXPECT_EQ(all(AgreeingAnswers(backwards, o)), 60);
  o.direction = SequenceDirection::kBoth;
  EXPECT_EQ(all(AgreeingAnswers(backwards, o)), 60);
}

// n partners: a chain back (each agreeing with the one before), then forward from q.
TEST(Agreement, SeveralPartnersFormAChain) {
  AgreementOptions o;
  o.sequence_length = 10;
  o.partial = SequencePartial::kScale;  // windows q - 9 .. q: partners exactly 10 apart
  o.partners = 2;
  std::vector<int> best(50);
  for (int q = 0; q < 50; ++q) best[q] = 100 + q;
  best[5] = 700;  // wrong: queries 15 (chain 5) and 25 (chain 15, 5) lose, 35 keeps 25, 15
  const std::vector<std::uint8_t> a = AgreeingAnswers(best, o);
  EXPECT_EQ(a[5], 0);
  EXPECT_EQ(a[15], 0);
  EXPECT_EQ(a[25], 0);
  EXPECT_EQ(a[35], 1);
  EXPECT_EQ(a[45], 1);
  // Query 9 has no partner back: forward 19, then 29.
  EXPECT_EQ(a[9], 1);
  best[29] = 5;
  EXPECT_EQ(AgreeingAnswers(best, o)[9], 0);
  o.partners = 0;
  EXPECT_THROW(AgreeingAnswers(best, o), std::logic_error);
}

}  // namespace
}  // namespace openable
