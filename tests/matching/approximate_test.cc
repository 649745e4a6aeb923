#include "matching/search/approximate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "tests/matching/random_rows.h"

namespace openable {
namespace {

using matching_test::RandomBytes;
using matching_test::RandomFloats;

// Row i of the result: row source[i] of `refs` with `bits` distinct bits flipped.
cv::Mat FlipBits(const cv::Mat& refs, const std::vector<int>& source, int bits, unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat out(static_cast<int>(source.size()), refs.cols, CV_8U);
  std::vector<int> positions(static_cast<size_t>(refs.cols) * 8);
  for (size_t i = 0; i < positions.size(); ++i) positions[i] = static_cast<int>(i);
  for (int i = 0; i < out.rows; ++i) {
    refs.row(source[static_cast<size_t>(i)]).copyTo(out.row(i));
    std::shuffle(positions.begin(), positions.end(), rng);
    for (int b = 0; b < bits; ++b)
      out.at<std::uint8_t>(i, positions[static_cast<size_t>(b)] / 8) ^=
          static_cast<std::uint8_t>(1u << (positions[static_cast<size_t>(b)] % 8));
  }
  return out;
}

// Row i: row source[i] of `refs` plus Gaussian noise of deviation `sigma`.
cv::Mat AddNoise(const cv::Mat& refs, const std::vector<int>& source, float sigma, unsigned seed) {
  cv::Mat out(static_cast<int>(source.size()), refs.cols, CV_32F);
  const cv::Mat noise = RandomFloats(out.rows, refs.cols, seed, 0, sigma);
  for (int i = 0; i < out.rows; ++i)
    out.row(i) = refs.row(source[static_cast<size_t>(i)]) + noise.row(i);
  return out;
}

std::vector<int> EveryNth(int count, int step) {
  std::vector<int> v;
  for (int i = 0; i < count; i += step) v.push_back(i);
  return v;
}

// Naive distances, written independently of the library: bit by bit, and a double sum.
float NaiveDistance(const cv::Mat& refs, int r, const cv::Mat& queries, int q) {
  if (refs.depth() == CV_8U) {
    int bits = 0;
    for (int k = 0; k < refs.cols; ++k)
      for (int bit = 0; bit < 8; ++bit)
        bits += ((refs.at<std::uint8_t>(r, k) >> bit) & 1) !=
                ((queries.at<std::uint8_t>(q, k) >> bit) & 1);
    return static_cast<float>(bits);
  }
  double s = 0;
  for (int k = 0; k < refs.cols; ++k) {
    const double t = static_cast<double>(refs.at<float>(r, k)) - queries.at<float>(q, k);
    s += t * t;
  }
  return static_cast<float>(std::sqrt(s));
}

// The k nearest by a double loop: every pair, sorted by (distance, reference).
CandidateLists NaiveNearest(const cv::Mat& refs, const cv::Mat& queries, int k) {
  CandidateLists out(static_cast<size_t>(queries.rows));
  for (int q = 0; q < queries.rows; ++q) {
    std::vector<Candidate>& all = out[static_cast<size_t>(q)];
    for (int r = 0; r < refs.rows; ++r) all.push_back({r, NaiveDistance(refs, r, queries, q)});
    std::stable_sort(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) {
      return a.distance < b.distance;
    });
    all.resize(static_cast<size_t>(std::min(k, refs.rows)));
  }
  return out;
}

void ExpectSameLists(const CandidateLists& expected, const CandidateLists& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t q = 0; q < expected.size(); ++q) {
    ASSERT_EQ(expected[q].size(), actual[q].size()) << "query " << q;
    for (size_t i = 0; i < expected[q].size(); ++i) {
      EXPECT_EQ(expected[q][i].reference, actual[q][i].reference) << "query " << q << " rank " << i;
      EXPECT_EQ(expected[q][i].distance, actual[q][i].distance) << "query " << q << " rank " << i;
    }
  }
}

// Every candidate's distance is the naive distance of its pair; lists sorted by (distance,
// reference), without repeats, at most k long.
void ExpectExactDistances(const cv::Mat& refs, const cv::Mat& queries, const CandidateLists& lists,
                          int k) {
  ASSERT_EQ(lists.size(), static_cast<size_t>(queries.rows));
  for (int q = 0; q < queries.rows; ++q) {
    const std::vector<Candidate>& list = lists[static_cast<size_t>(q)];
    ASSERT_LE(list.size(), static_cast<size_t>(k));
    for (size_t i = 0; i < list.size(); ++i) {
      ASSERT_GE(list[i].reference, 0);
      ASSERT_LT(list[i].reference, refs.rows);
      EXPECT_EQ(list[i].distance, NaiveDistance(refs, list[i].reference, queries, q))
          << "query " << q << " reference " << list[i].reference;
      if (i > 0) {
        const bool ordered =
            list[i - 1].distance < list[i].distance ||
            (list[i - 1].distance == list[i].distance && list[i - 1].reference < list[i].reference);
        EXPECT_TRUE(ordered) << "query " << q << " rank " << i;
      }
    }
  }
}

bool SameLists(const CandidateLists& a, const CandidateLists& b) {
  if (a.size() != b.size()) return false;
  for (size_t q = 0; q < a.size(); ++q) {
    if (a[q].size() != b[q].size()) return false;
    for (size_t i = 0; i < a[q].size(); ++i)
      if (a[q][i].reference != b[q][i].reference || a[q][i].distance != b[q][i].distance)
        return false;
  }
  return true;
}

// ---------------------------------------------------------------- exact search

TEST(ExactNearest, HammingMatchesDoubleLoop) {
  // 2-byte descriptors over 300 references: many equal distances, so the tie order is tested.
  for (int width : {2, 32, 13}) {
    SCOPED_TRACE(width);
    const cv::Mat refs = RandomBytes(300, width, 10 + width);
    const cv::Mat queries = RandomBytes(40, width, 20 + width);
    for (int k : {1, 7, 300}) {
      SCOPED_TRACE(k);
      for (int threads : {1, 3})
        ExpectSameLists(NaiveNearest(refs, queries, k), ExactNearest(refs, queries, k, threads));
    }
  }
}

TEST(ExactNearest, L2MatchesDoubleLoop) {
  // A large common offset makes |q|^2 + |r|^2 - 2 q.r cancel: the matrix product alone would
  // misrank these; the exact recomputation must not. Also plain unit Gaussians, and exact
  // duplicates of references (distance 0, ties by index).
  for (float offset : {0.0f, 100.0f}) {
    SCOPED_TRACE(offset);
    for (int width : {1, 64, 300}) {
      SCOPED_TRACE(width);
      cv::Mat refs = RandomFloats(400, width, 30 + width, offset, 0.01f);
      refs.row(5).copyTo(refs.row(17));
      cv::Mat queries = RandomFloats(30, width, 40 + width, offset, 0.01f);
      refs.row(17).copyTo(queries.row(3));
      for (int k : {1, 10, 400}) {
        SCOPED_TRACE(k);
        ExpectSameLists(NaiveNearest(refs, queries, k), ExactNearest(refs, queries, k, 2));
      }
    }
  }
}

TEST(ExactNearest, KLargerThanReferencesGivesThemAll) {
  const cv::Mat refs = RandomBytes(5, 32, 1), queries = RandomBytes(3, 32, 2);
  const CandidateLists exact = ExactNearest(refs, queries, 10);
  for (const auto& list : exact) EXPECT_EQ(list.size(), 5u);
  ExpectSameLists(NaiveNearest(refs, queries, 10), exact);
}

TEST(ExactNearest, ViewsAndEmptyQueries) {
  const cv::Mat big = RandomFloats(60, 40, 3);
  const cv::Mat refs = big(cv::Rect(5, 0, 30, 50)), queries = big(cv::Rect(5, 50, 30, 10));
  ASSERT_FALSE(refs.isContinuous());
  ExpectSameLists(NaiveNearest(refs, queries, 4), ExactNearest(refs, queries, 4));
  EXPECT_TRUE(ExactNearest(refs, cv::Mat(0, 30, CV_32F), 4).empty());
  EXPECT_TRUE(ExactNearest(refs, cv::Mat(), 4).empty());
}

// ---------------------------------------------------------------- approximate search

// FLANN's options (the default engine is auto: IVF or HNSW).
ApproximateOptions FlannOptions() {
  ApproximateOptions o;
  o.engine = "flann";
  return o;
}

// 2000 random 256-bit references; queries are every 4th reference with 8 bits flipped (a
// planted near-duplicate at distance 8, while other references lie around 128).
TEST(ApproximateIndex, LshFindsPlantedNearDuplicates) {
  const cv::Mat refs = RandomBytes(2000, 32, 7);
  const cv::Mat queries = FlipBits(refs, EveryNth(2000, 4), 8, 8);
  ApproximateOptions options = FlannOptions();
  const ApproximateIndex index(refs, options);
  EXPECT_EQ(index.Size(), 2000);
  EXPECT_EQ(index.Width(), 32);
  EXPECT_EQ(index.Type(), CV_8U);
  const CandidateLists approximate = index.Search(queries);
  ExpectExactDistances(refs, queries, approximate, options.k);
  const CandidateLists exact = ExactNearest(refs, queries, options.k);
  const SearchRecall recall = MeasureRecall(exact, approximate);
  EXPECT_EQ(recall.queries, 500);
  // Measured top1 1.000 with the default options: level-2 probing finds the planted row
  // whenever a table's 20-bit key holds at most 2 of the 8 flipped bits (probability 0.98),
  // so all 12 tables miss with probability ~1e-21.
  EXPECT_GE(recall.top1, 0.99);
  // Measured at_k 0.130: the other 9 exact neighbours are unrelated rows ~100 bits away, which
  // rarely share a probed bucket with the query; the planted one alone gives 0.1.
  EXPECT_GE(recall.at_k, 0.1);
}

// Without probing and with one table LSH misses planted neighbours at distance 40 often; with
// the defaults far less. Guards against the LSH options being ignored.
TEST(ApproximateIndex, LshOptionsChangeRecall) {
  const cv::Mat refs = RandomBytes(2000, 32, 11);
  const cv::Mat queries = FlipBits(refs, EveryNth(2000, 4), 40, 12);
  const CandidateLists exact = ExactNearest(refs, queries, 10);
  ApproximateOptions weak = FlannOptions();
  weak.lsh_tables = 1;
  weak.lsh_probe_level = 0;
  const SearchRecall low = MeasureRecall(exact, ApproximateIndex(refs, weak).Search(queries));
  const SearchRecall high =
      MeasureRecall(exact, ApproximateIndex(refs, FlannOptions()).Search(queries));
  // One table, no probing: found only when the 20 key bits avoid all 40 flipped bits
  // (probability 0.029; measured top1 0.032). Defaults, 12 tables probed at level 2: found
  // unless every key holds 3 or more (1 - 0.634^12 = 0.996; measured 0.998).
  EXPECT_LE(low.top1, 0.15);
  EXPECT_GE(high.top1, 0.9);
}

// Float vectors: 2000 references of 64 unit Gaussians; queries every 4th reference plus noise of
// deviation 0.1 (the planted neighbour at ~0.8, others at ~11).
TEST(ApproximateIndex, KdTreesFindPlantedNearDuplicates) {
  const cv::Mat refs = RandomFloats(2000, 64, 21);
  const cv::Mat queries = AddNoise(refs, EveryNth(2000, 4), 0.1f, 22);
  ApproximateOptions options = FlannOptions();
  options.checks = 128;
  const ApproximateIndex index(refs, options);
  EXPECT_EQ(index.Type(), CV_32F);
  const CandidateLists approximate = index.Search(queries);
  ExpectExactDistances(refs, queries, approximate, options.k);
  for (const auto& list : approximate) EXPECT_EQ(list.size(), 10u);  // k-d trees fill k
  const CandidateLists exact = ExactNearest(refs, queries, options.k);
  const SearchRecall recall = MeasureRecall(exact, approximate);
  // Measured top1 1.000, at_k 0.355 with 128 checks (the 9 other neighbours are unrelated
  // rows at ~11, hard for k-d trees in 64 dimensions).
  EXPECT_GE(recall.top1, 0.95);
  EXPECT_GE(recall.at_k, 0.25);
  // A budget of 2 x the references examines all of them: exact (measured 1.000 and 1.000).
  options.checks = 4000;
  const SearchRecall full = MeasureRecall(exact, ApproximateIndex(refs, options).Search(queries));
  EXPECT_GE(full.top1, recall.top1);
  EXPECT_GE(full.at_k, 0.99);
}

// Two sets of `rows` references of 32 columns and their queries (every 3rd reference, altered):
// random bytes with `flipped_bits` bits flipped (seeds `seed`, `seed` + 1), and unit Gaussians
// plus noise of deviation 0.5 (seeds `seed` + 2, `seed` + 3).
std::vector<std::pair<cv::Mat, cv::Mat>> BinaryAndFloatRows(int rows, int flipped_bits,
                                                            unsigned seed) {
  const cv::Mat bytes = RandomBytes(rows, 32, seed);
  const cv::Mat floats = RandomFloats(rows, 32, seed + 2);
  return {{bytes, FlipBits(bytes, EveryNth(rows, 3), flipped_bits, seed + 1)},
          {floats, AddNoise(floats, EveryNth(rows, 3), 0.5f, seed + 3)}};
}

TEST(ApproximateIndex, DeterministicAcrossBuildsAndThreads) {
  for (const auto& [refs, queries] : BinaryAndFloatRows(1000, 30, 31)) {
    ApproximateOptions one = FlannOptions(), two = one;
    one.threads = 1;
    two.threads = 2;
    one.checks = two.checks = 32;
    cv::theRNG() = cv::RNG(1);  // the caller's generator must not matter...
    const CandidateLists a = ApproximateIndex(refs, one).Search(queries);
    cv::theRNG() = cv::RNG(2);
    const CandidateLists b = ApproximateIndex(refs, two).Search(queries);
    EXPECT_TRUE(SameLists(a, b));
    // ...and is given back unchanged.
    cv::RNG before = cv::theRNG();
    const ApproximateIndex index(refs, one);
    EXPECT_EQ(before.state, cv::theRNG().state);
    // Another seed builds another index (different candidates somewhere).
    ApproximateOptions other = one;
    other.seed = 12345;
    EXPECT_FALSE(SameLists(a, ApproximateIndex(refs, other).Search(queries)));
  }
}

TEST(ApproximateIndex, ConcurrentSearchesAgree) {
  const cv::Mat floats = RandomFloats(1000, 32, 35);
  const cv::Mat bytes = RandomBytes(1000, 32, 36);
  for (const cv::Mat& refs : {floats, bytes}) {
    ApproximateOptions options = FlannOptions();
    options.threads = 2;
    const ApproximateIndex index(refs, options);
    const CandidateLists alone = index.Search(refs);
    CandidateLists results[3];
    std::vector<std::thread> threads;
    for (auto& r : results) threads.emplace_back([&index, &refs, &r] { r = index.Search(refs); });
    for (auto& t : threads) t.join();
    for (const auto& r : results) EXPECT_TRUE(SameLists(alone, r));
  }
}

TEST(ApproximateIndex, KLargerThanReferences) {
  const cv::Mat refs = RandomFloats(5, 8, 41), queries = RandomFloats(3, 8, 42);
  ApproximateOptions options = FlannOptions();
  options.k = 10;
  const CandidateLists kd = ApproximateIndex(refs, options).Search(queries);
  ExpectSameLists(NaiveNearest(refs, queries, 10), kd);  // all 5, in order

  const cv::Mat bytes = RandomBytes(5, 32, 43);
  const CandidateLists lsh = ApproximateIndex(bytes, options).Search(bytes);
  for (int q = 0; q < 5; ++q) {
    ASSERT_GE(lsh[static_cast<size_t>(q)].size(), 1u);
    ASSERT_LE(lsh[static_cast<size_t>(q)].size(), 5u);
    EXPECT_EQ(lsh[static_cast<size_t>(q)][0].reference, q);  // itself, distance 0
    EXPECT_EQ(lsh[static_cast<size_t>(q)][0].distance, 0.0f);
  }
}

TEST(ApproximateIndex, NarrowDescriptorsCapTheKey) {
  // 1-byte descriptors: a 20-bit key cannot be drawn from 8 bits; it is capped, not a crash.
  const cv::Mat refs = RandomBytes(200, 1, 51), queries = RandomBytes(20, 1, 52);
  const CandidateLists approximate = ApproximateIndex(refs, FlannOptions()).Search(queries);
  ExpectExactDistances(refs, queries, approximate, 10);
  // An 8-bit key over 8-bit descriptors: each table's bucket holds the equal references, and
  // probing level 2 reaches every reference within 2 bits.
  for (int q = 0; q < queries.rows; ++q)
    for (const Candidate& c : approximate[static_cast<size_t>(q)]) EXPECT_LE(c.distance, 2.0f);
}

TEST(ApproximateIndex, ViewsAndEmptyQueries) {
  const cv::Mat big = RandomFloats(60, 40, 61);
  const cv::Mat refs = big(cv::Rect(5, 0, 30, 50)), queries = big(cv::Rect(5, 50, 30, 10));
  ApproximateOptions options = FlannOptions();
  options.checks = 1000;  // more than the references: exact
  const ApproximateIndex index(refs, options);
  ExpectSameLists(NaiveNearest(refs, queries, 10), index.Search(queries));
  EXPECT_TRUE(index.Search(cv::Mat(0, 30, CV_32F)).empty());
  EXPECT_TRUE(index.Search(cv::Mat()).empty());
}

TEST(ApproximateIndex, MovesKeepTheIndex) {
  const cv::Mat refs = RandomBytes(100, 32, 71);
  ApproximateIndex a(refs, FlannOptions());
  const CandidateLists before = a.Search(refs);
  ApproximateIndex b(std::move(a));
  EXPECT_TRUE(SameLists(before, b.Search(refs)));
}

// ---------------------------------------------------------------- invalid input

TEST(ApproximateIndex, RejectsBadOptionsAndInputs) {
  const cv::Mat bytes = RandomBytes(10, 32, 81), floats = RandomFloats(10, 32, 82);
  auto with = [](auto change) {
    ApproximateOptions o = FlannOptions();
    change(o);
    return o;
  };
  const ApproximateOptions bad[] = {
      with([](ApproximateOptions& o) { o.k = 0; }),
      with([](ApproximateOptions& o) { o.checks = 0; }),
      with([](ApproximateOptions& o) { o.lsh_tables = 0; }),
      with([](ApproximateOptions& o) { o.lsh_key_bits = 0; }),
      with([](ApproximateOptions& o) { o.lsh_key_bits = 33; }),
      with([](ApproximateOptions& o) { o.lsh_probe_level = -1; }),
      with([](ApproximateOptions& o) { o.lsh_probe_level = 4; }),
      with([](ApproximateOptions& o) { o.kd_trees = 0; }),
      with([](ApproximateOptions& o) { o.threads = -1; }),
  };
  for (const ApproximateOptions& o : bad) {
    EXPECT_THROW(o.Check(), std::invalid_argument);
    EXPECT_THROW(ApproximateIndex(bytes, o), std::invalid_argument);
    EXPECT_THROW(ApproximateIndex(floats, o), std::invalid_argument);
  }
  try {
    bad[0].Check();
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("k = 0"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }

  const ApproximateOptions ok = FlannOptions();
  EXPECT_THROW(ApproximateIndex(cv::Mat(), ok), std::invalid_argument);
  EXPECT_THROW(ApproximateIndex(cv::Mat(0, 32, CV_8U), ok), std::invalid_argument);
  EXPECT_THROW(ApproximateIndex(cv::Mat(10, 32, CV_16U, cv::Scalar(0)), ok), std::invalid_argument);
  EXPECT_THROW(ApproximateIndex(cv::Mat(10, 32, CV_8UC3, cv::Scalar(0)), ok),
               std::invalid_argument);
  cv::Mat nan = floats.clone();
  nan.at<float>(3, 4) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(ApproximateIndex(nan, ok), std::invalid_argument);

  const ApproximateIndex lsh(bytes, ok), kd(floats, ok);
  EXPECT_THROW(lsh.Search(RandomBytes(3, 16, 83)), std::invalid_argument);  // width
  EXPECT_THROW(lsh.Search(floats), std::invalid_argument);                  // type
  EXPECT_THROW(kd.Search(bytes), std::invalid_argument);
  EXPECT_THROW(kd.Search(nan), std::invalid_argument);
  EXPECT_THROW(kd.Search(RandomFloats(3, 31, 84)), std::invalid_argument);
}

TEST(ExactNearest, RejectsBadInputs) {
  const cv::Mat bytes = RandomBytes(10, 32, 91), floats = RandomFloats(10, 32, 92);
  EXPECT_THROW(ExactNearest(bytes, bytes, 0), std::invalid_argument);
  EXPECT_THROW(ExactNearest(bytes, bytes, 3, -1), std::invalid_argument);
  EXPECT_THROW(ExactNearest(cv::Mat(), bytes, 3), std::invalid_argument);
  EXPECT_THROW(ExactNearest(bytes, floats, 3), std::invalid_argument);
  EXPECT_THROW(ExactNearest(bytes, RandomBytes(2, 31, 93), 3), std::invalid_argument);
  EXPECT_THROW(ExactNearest(cv::Mat(4, 4, CV_64F, cv::Scalar(0)), cv::Mat(4, 4, CV_64F), 1),
               std::invalid_argument);
}

// ---------------------------------------------------------------- recall

TEST(MeasureRecall, TiesCountAndAtKCounts) {
  const CandidateLists exact = {
      {{0, 1}, {1, 2}, {2, 3}},
      {{5, 0}, {6, 0}, {7, 4}},
      {{3, 1}, {4, 5}, {8, 9}},
      {{1, 2}, {2, 2}, {3, 2}},
  };
  const CandidateLists approximate = {
      {{0, 1}, {1, 2}, {2, 3}},  // all found: top1, 3/3
      {{6, 0}, {9, 4}, {2, 7}},  // another reference at the nearest distance counts; 9 ties
                                 // the 3rd (4): 2/3
      {{4, 5}},                  // nearest missed, one of 3 found: 1/3
      {},                        // nothing: 0
  };
  const SearchRecall r = MeasureRecall(exact, approximate);
  EXPECT_EQ(r.queries, 4);
  EXPECT_DOUBLE_EQ(r.top1, 2.0 / 4);
  EXPECT_DOUBLE_EQ(r.at_k, (1.0 + 2.0 / 3 + 1.0 / 3 + 0) / 4);
  EXPECT_DOUBLE_EQ(MeasureRecall(exact, exact).top1, 1.0);
  EXPECT_DOUBLE_EQ(MeasureRecall(exact, exact).at_k, 1.0);
  EXPECT_EQ(MeasureRecall({}, {}).queries, 0);
  EXPECT_THROW(MeasureRecall(exact, {}), std::invalid_argument);
  EXPECT_THROW(MeasureRecall({{}}, {{}}), std::invalid_argument);
}

// ---------------------------------------------------------------- FAISS engines

// The FAISS engines of this build, with a message when there are none.
#define SKIP_WITHOUT_FAISS() \
  if (!FaissAvailable()) GTEST_SKIP() << "this build has no FAISS (libfaiss-dev)"

ApproximateOptions EngineOptions(const std::string& engine) {
  ApproximateOptions o;
  o.engine = engine;
  return o;
}

// Share of queries whose first candidate is the planted reference (query i made from
// reference source[i]).
double PlantedFound(const CandidateLists& lists, const std::vector<int>& source) {
  int found = 0;
  for (size_t q = 0; q < lists.size(); ++q)
    found += !lists[q].empty() && lists[q][0].reference == source[q];
  return static_cast<double>(found) / static_cast<double>(lists.size());
}

// Each Faiss engine on `refs` and `queries` (query q near reference source[q]): the index holds
// rows of `type`, its candidates carry exact distances, and for at least 98% of the queries its
// first candidate is the planted row and the exact nearest.
void ExpectFaissEnginesFindThePlantedRows(const cv::Mat& refs, const cv::Mat& queries,
                                          const std::vector<int>& source, int type) {
  const CandidateLists exact = ExactNearest(refs, queries, 10);
  for (const std::string engine : {"hnsw", "ivf"}) {
    SCOPED_TRACE(engine);
    const ApproximateIndex index(refs, EngineOptions(engine));
    EXPECT_EQ(index.Type(), type);
    const CandidateLists approximate = index.Search(queries);
    ExpectExactDistances(refs, queries, approximate, 10);
    EXPECT_GE(PlantedFound(approximate, source), 0.98);
    EXPECT_GE(MeasureRecall(exact, approximate).top1, 0.98);
  }
}

// 4000 random 256-bit references; queries every 4th with 8 bits flipped (the planted row at 8
// bits, every other ~128 away). Each engine must find the planted row, with exact distances.
// HNSW: the planted row is far nearer than any other, the graph search reaches it. IVF: cells
// are k-means of random bits; 8 flipped bits rarely move a query out of its source's nearest 16
// cells (of 102).
TEST(ApproximateIndex, FaissBinaryIndexesFindPlantedNearDuplicates) {
  SKIP_WITHOUT_FAISS();
  const cv::Mat refs = RandomBytes(4000, 32, 101);
  const std::vector<int> source = EveryNth(4000, 4);
  const cv::Mat queries = FlipBits(refs, source, 8, 102);
  EXPECT_DOUBLE_EQ(PlantedFound(ExactNearest(refs, queries, 10), source), 1.0);
  ExpectFaissEnginesFindThePlantedRows(refs, queries, source, CV_8U);
}

// 4000 float references of 64 unit Gaussians; queries every 4th plus noise of deviation 0.1.
TEST(ApproximateIndex, FaissFloatIndexesFindPlantedNearDuplicates) {
  SKIP_WITHOUT_FAISS();
  const cv::Mat refs = RandomFloats(4000, 64, 111);
  const std::vector<int> source = EveryNth(4000, 4);
  ExpectFaissEnginesFindThePlantedRows(refs, AddNoise(refs, source, 0.1f, 112), source, CV_32F);
}

// The search budget is used: a tiny IVF probe or HNSW list finds fewer of the exact 10 nearest
// than a large one on unstructured rows (no planted neighbour).
TEST(ApproximateIndex, FaissSearchBudgetChangesRecall) {
  SKIP_WITHOUT_FAISS();
  const cv::Mat refs = RandomFloats(4000, 32, 121), queries = RandomFloats(200, 32, 122);
  const CandidateLists exact = ExactNearest(refs, queries, 10);
  ApproximateOptions small = EngineOptions("ivf"), large = small;
  small.nprobe = 1;
  large.nprobe = 1000;  // every cell: exact
  EXPECT_LT(MeasureRecall(exact, ApproximateIndex(refs, small).Search(queries)).at_k, 0.8);
  EXPECT_DOUBLE_EQ(MeasureRecall(exact, ApproximateIndex(refs, large).Search(queries)).at_k, 1.0);
  small = large = EngineOptions("hnsw");
  small.ef_search = 1;  // raised to k = 10
  large.ef_search = 2000;
  EXPECT_LT(MeasureRecall(exact, ApproximateIndex(refs, small).Search(queries)).at_k,
            MeasureRecall(exact, ApproximateIndex(refs, large).Search(queries)).at_k);
}

TEST(ApproximateIndex, BinaryIvfScansItsCellsWithExactDistances) {
  // The binary IVF index scans FAISS's cells itself (matching/search/approximate.cc, IvfCells):
  // probing every cell must give the brute-force lists, ties included (2-byte rows: many equal
  // distances; 13 bytes: a width that is not a multiple of the kernels' words), and probing one
  // cell only true distances, each reference once, in order.
  SKIP_WITHOUT_FAISS();
  for (const int width : {2, 13, 32}) {
    SCOPED_TRACE(width);
    const cv::Mat refs = RandomBytes(3000, width, 150 + width);
    const cv::Mat queries = FlipBits(refs, EveryNth(3000, 25), 4 * width / 8 + 1, 160 + width);
    ApproximateOptions all = EngineOptions("ivf"), one = all;
    all.nprobe = 65536;
    one.nprobe = 1;
    ExpectSameLists(NaiveNearest(refs, queries, all.k),
                    ApproximateIndex(refs, all).Search(queries));
    const CandidateLists lists = ApproximateIndex(refs, one).Search(queries);
    for (int q = 0; q < queries.rows; ++q) {
      const std::vector<Candidate>& list = lists[static_cast<size_t>(q)];
      ASSERT_FALSE(list.empty());
      for (std::size_t i = 0; i < list.size(); ++i) {
        EXPECT_EQ(list[i].distance,
                  cv::norm(queries.row(q), refs.row(list[i].reference), cv::NORM_HAMMING));
        if (i > 0) {
          EXPECT_TRUE(list[i - 1].distance < list[i].distance ||
                      (list[i - 1].distance == list[i].distance &&
                       list[i - 1].reference < list[i].reference));
        }
      }
    }
  }
}

TEST(ApproximateIndex, AutoEngineIsIvfForBinaryRowsAndHnswForFloatRows) {
  EXPECT_EQ(ResolvedEngine("auto", CV_8U), "ivf");
  EXPECT_EQ(ResolvedEngine("auto", CV_32F), "hnsw");
  EXPECT_EQ(ResolvedEngine("flann", CV_8U), "flann");
  EXPECT_EQ(ResolvedEngine("hnsw", CV_8U), "hnsw");
  SKIP_WITHOUT_FAISS();
  // The index built with auto is the one built with the resolved engine: same candidates.
  const cv::Mat bytes = RandomBytes(2000, 32, 171), floats = RandomFloats(2000, 16, 172);
  for (const cv::Mat& refs : {bytes, floats}) {
    const cv::Mat queries = refs.rowRange(0, 100);
    ApproximateOptions automatic;
    ApproximateOptions resolved = automatic;
    resolved.engine = refs.depth() == CV_8U ? "ivf" : "hnsw";
    const ApproximateIndex index(refs, automatic);
    EXPECT_EQ(index.Options().engine, resolved.engine);
    EXPECT_TRUE(SameLists(index.Search(queries), ApproximateIndex(refs, resolved).Search(queries)));
  }
}

TEST(ApproximateIndex, FaissDeterministicAcrossBuildsAndThreads) {
  SKIP_WITHOUT_FAISS();
  for (const auto& [refs, queries] : BinaryAndFloatRows(3000, 40, 131)) {
    for (const std::string engine : {"hnsw", "ivf"}) {
      SCOPED_TRACE(engine + (refs.depth() == CV_8U ? " binary" : " float"));
      ApproximateOptions one = EngineOptions(engine), two = one;
      one.threads = 1;
      two.threads = 2;
      one.ef_search = two.ef_search = 16;
      one.nprobe = two.nprobe = 2;
      const CandidateLists a = ApproximateIndex(refs, one).Search(queries);
      const CandidateLists b = ApproximateIndex(refs, two).Search(queries);
      const CandidateLists c = ApproximateIndex(refs, two).Search(queries);
      EXPECT_TRUE(SameLists(a, b));
      EXPECT_TRUE(SameLists(b, c));
      if (engine == "ivf") {  // the k-means seed is used
        ApproximateOptions other = one;
        other.seed = 12345;
        EXPECT_FALSE(SameLists(a, ApproximateIndex(refs, other).Search(queries)));
      }
    }
  }
}

TEST(ApproximateIndex, FaissSmallSetsAndConcurrentSearches) {
  SKIP_WITHOUT_FAISS();
  for (const std::string engine : {"hnsw", "ivf"}) {
    SCOPED_TRACE(engine);
    // Fewer references than k (IVF: one cell): every one, in order.
    const cv::Mat refs = RandomFloats(5, 8, 141), queries = RandomFloats(3, 8, 142);
    ExpectSameLists(NaiveNearest(refs, queries, 10),
                    ApproximateIndex(refs, EngineOptions(engine)).Search(queries));
    const cv::Mat bytes = RandomBytes(1000, 32, 143);
    ApproximateOptions options = EngineOptions(engine);
    options.threads = 2;
    const ApproximateIndex index(bytes, options);
    const CandidateLists alone = index.Search(bytes);
    for (int q = 0; q < bytes.rows; ++q) EXPECT_EQ(alone[static_cast<size_t>(q)][0].distance, 0);
    CandidateLists results[3];
    std::vector<std::thread> threads;
    for (auto& r : results) threads.emplace_back([&index, &bytes, &r] { r = index.Search(bytes); });
    for (auto& t : threads) t.join();
    for (const auto& r : results) EXPECT_TRUE(SameLists(alone, r));
    EXPECT_TRUE(index.Search(cv::Mat(0, 32, CV_8U)).empty());
    EXPECT_THROW(index.Search(RandomBytes(2, 16, 144)), std::invalid_argument);
  }
}

TEST(ApproximateIndex, RejectsBadFaissOptions) {
  const cv::Mat bytes = RandomBytes(10, 32, 151);
  auto with = [](auto change) {
    ApproximateOptions o = EngineOptions("hnsw");
    change(o);
    return o;
  };
  const std::pair<ApproximateOptions, const char*> bad[] = {
      {with([](ApproximateOptions& o) { o.engine = "annoy"; }),
       "engine = \"annoy\", expected one of flann, hnsw, ivf, binary_ivf or auto"},
      {with([](ApproximateOptions& o) { o.hnsw_m = 2; }), "hnsw_m = 2, expected 4..128"},
      {with([](ApproximateOptions& o) { o.hnsw_ef_construction = 0; }), "hnsw_ef_construction = 0"},
      {with([](ApproximateOptions& o) { o.ef_search = 0; }), "ef_search = 0, expected 1..100000"},
      {with([](ApproximateOptions& o) { o.ivf_lists = -1; }), "ivf_lists = -1"},
      {with([](ApproximateOptions& o) { o.nprobe = 0; }), "nprobe = 0, expected 1..65536"},
  };
  for (const auto& [o, expected] : bad) {
    try {
      ApproximateIndex index(bytes, o);
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(expected), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

// A build without FAISS refuses its engines with one line naming the key; with FAISS they are
// accepted. FLANN is always available.
TEST(ApproximateIndex, FaissEnginesNeedFaissInTheBuild) {
  EXPECT_NO_THROW(CheckEngineAvailable("flann", "Approximate_engine"));
  for (const std::string engine : {"hnsw", "ivf"}) {
    if (FaissAvailable()) {
      EXPECT_NO_THROW(CheckEngineAvailable(engine, "Approximate_engine"));
      continue;
    }
    try {
      CheckEngineAvailable(engine, "Approximate_engine");
      ADD_FAILURE() << "accepted without FAISS";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("Approximate_engine: " + engine, 0), 0u) << e.what();
    }
    EXPECT_THROW(ApproximateIndex(RandomBytes(10, 32, 161), EngineOptions(engine)), InputError);
  }
}

// The binary_ivf engine against brute force: probing every cell gives the exact k nearest
// (the same rows, distances and tie order as ExactNearest); a few cells find the near
// duplicates planted in the references; the index is the same on one and two threads, and the
// index read back from its bytes gives the same candidates.
TEST(BinaryIvf, EveryCellProbedIsExactAndFewCellsFindNearDuplicates) {
  std::mt19937 rng(3);
  cv::Mat refs(5000, 32, CV_8U);
  for (int i = 0; i < refs.rows; ++i)
    for (int b = 0; b < refs.cols; ++b)
      refs.at<std::uint8_t>(i, b) = static_cast<std::uint8_t>(rng());
  // Queries: 60 references with 8 of their 256 bits flipped, and 20 random rows.
  cv::Mat queries(80, 32, CV_8U);
  std::vector<int> planted;
  for (int q = 0; q < 60; ++q) {
    const int r = static_cast<int>(rng() % 5000);
    planted.push_back(r);
    refs.row(r).copyTo(queries.row(q));
    for (int f = 0; f < 8; ++f) {
      const int bit = static_cast<int>(rng() % 256);
      queries.at<std::uint8_t>(q, bit / 8) ^= static_cast<std::uint8_t>(1u << (bit % 8));
    }
  }
  for (int q = 60; q < 80; ++q)
    for (int b = 0; b < 32; ++b) queries.at<std::uint8_t>(q, b) = static_cast<std::uint8_t>(rng());
  ApproximateOptions options;
  options.engine = "binary_ivf";
  options.k = 7;
  options.ivf_lists = 40;
  options.nprobe = 40;
  options.threads = 1;
  const ApproximateIndex index(refs, options);
  const CandidateLists exact = ExactNearest(refs, queries, 7, 1);
  const CandidateLists all = index.Search(queries);
  ASSERT_EQ(all.size(), exact.size());
  for (std::size_t q = 0; q < all.size(); ++q) {
    ASSERT_EQ(all[q].size(), exact[q].size()) << q;
    for (std::size_t i = 0; i < all[q].size(); ++i) {
      EXPECT_EQ(all[q][i].reference, exact[q][i].reference) << q << " " << i;
      EXPECT_EQ(all[q][i].distance, exact[q][i].distance) << q << " " << i;
    }
  }
  // Two cells of 40: the planted row is its query's nearest by far (8 bits against about 128)
  // and lies in a cell near it.
  ApproximateOptions few = options;
  few.nprobe = 2;
  const ApproximateIndex narrow(refs, few);
  const CandidateLists found = narrow.Search(queries);
  int hits = 0;
  for (int q = 0; q < 60; ++q)
    hits += !found[static_cast<std::size_t>(q)].empty() &&
            found[static_cast<std::size_t>(q)][0].reference == planted[static_cast<std::size_t>(q)];
  EXPECT_GE(hits, 40) << "planted rows found with 2 of 40 cells";
  // One thread or two: the same index; read back: the same candidates.
  ApproximateOptions two = options;
  two.threads = 2;
  EXPECT_EQ(ApproximateIndex(refs, two).Serialize(), index.Serialize());
  const ApproximateIndex read(refs, few, narrow.Serialize());
  const CandidateLists again = read.Search(queries);
  for (std::size_t q = 0; q < found.size(); ++q) {
    ASSERT_EQ(again[q].size(), found[q].size());
    for (std::size_t i = 0; i < found[q].size(); ++i)
      EXPECT_EQ(again[q][i].reference, found[q][i].reference);
  }
  // Bytes of another index, or of these cut short: refused.
  std::vector<std::uint8_t> bytes = index.Serialize();
  bytes.resize(bytes.size() - 4);
  EXPECT_THROW(ApproximateIndex(refs, options, bytes), std::invalid_argument);
  EXPECT_THROW(ApproximateIndex(refs.rowRange(0, 4000), options, index.Serialize()),
               std::invalid_argument);
}

}  // namespace
}  // namespace openable
