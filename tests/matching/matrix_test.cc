#include "matching/matrix.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "matching/normalize.h"
#include "tests/matching/random_rows.h"

namespace openable {
namespace {

using matching_test::RandomBytes;

// The two passes the one-pass matrix replaces: every distance, then the sequence sums
// (SequenceDistancesInPlace, tested against brute force in sequence_test.cc).
cv::Mat1f TwoPasses(const cv::Mat& rows, Metric metric, int L, SequenceDirection direction,
                    SequencePartial partial, const std::vector<int>& starts) {
  cv::Mat1f d = Distances(rows, cv::Mat(), metric, 2);
  SequenceDistancesInPlace(d, L, starts, starts, direction, 2, partial);
  return d;
}

// The one-pass matrix is the two passes' matrix bit for bit (integer distances: double sums
// are exact) for every direction, partial rule and L, one and two traversals, with rows
// enough that the ranges of rows of the pass start in many places; its largest value is the
// largest finite cell; and sampled cells equal SequenceCellDistance, the sum of the
// definition taken term by term.
TEST(FusedSequenceMatrix, IsTheTwoPassMatrixBitForBit) {
  const cv::Mat rows = RandomBytes(700, 32, 3);
  const cv::Mat sad = RandomBytes(300, 48, 4);
  // Bytes of 0 or 255 and 2048 of them: L1 distances near 261,000 (odd ones too), whose sums of
  // L = 80 pass 2^24, where float no longer holds every integer: the sums must be kept in
  // double there to stay exact.
  cv::Mat extremes = RandomBytes(200, 2048, 5);
  for (auto it = extremes.begin<std::uint8_t>(); it != extremes.end<std::uint8_t>(); ++it)
    *it = *it < 128 ? static_cast<std::uint8_t>(*it % 3) : static_cast<std::uint8_t>(255 - *it % 3);
  struct Case {
    const cv::Mat* rows;
    Metric metric;
    int L;
    SequenceDirection direction;
    SequencePartial partial;
    std::vector<int> starts;
  };
  const std::vector<Case> cases = {
      {&rows, Metric::kHamming, 1, SequenceDirection::kForward, SequencePartial::kAhead, {}},
      {&rows, Metric::kHamming, 10, SequenceDirection::kForward, SequencePartial::kAhead, {}},
      {&rows, Metric::kHamming, 10, SequenceDirection::kForward, SequencePartial::kAhead, {0, 420}},
      {&rows, Metric::kHamming, 7, SequenceDirection::kReverse, SequencePartial::kSkip, {0, 350}},
      {&rows, Metric::kHamming, 5, SequenceDirection::kBoth, SequencePartial::kScale, {}},
      {&rows, Metric::kHamming, 30, SequenceDirection::kBoth, SequencePartial::kAhead, {0, 333}},
      {&sad, Metric::kL1, 4, SequenceDirection::kForward, SequencePartial::kAhead, {0, 100}},
      {&extremes, Metric::kL1, 80, SequenceDirection::kForward, SequencePartial::kScale, {}},
  };
  for (const Case& c : cases) {
    const std::string what = "L " + std::to_string(c.L) + ", direction " +
                             std::to_string(static_cast<int>(c.direction)) + ", partial " +
                             std::to_string(static_cast<int>(c.partial)) + ", " +
                             std::to_string(c.starts.size()) + " traversal starts";
    float largest = -1.0f;
    const cv::Mat1f one =
        FusedSequenceMatrix(*c.rows, c.metric, c.L, c.direction, c.partial, c.starts, 2, largest);
    const cv::Mat1f two = TwoPasses(*c.rows, c.metric, c.L, c.direction, c.partial, c.starts);
    ASSERT_EQ(one.size(), two.size()) << what;
    for (int i = 0; i < one.rows; ++i)
      for (int j = 0; j < one.cols; ++j) {
        const float a = one(i, j), b = two(i, j);
        ASSERT_TRUE(a == b || (std::isinf(a) && std::isinf(b)))
            << what << ": cell " << i << "," << j << " is " << a << ", expected " << b;
      }
    EXPECT_EQ(largest, LargestFiniteEntry(two)) << what;
  }
  // Forward, one traversal: cells against the sum of their L terms.
  float largest = 0.0f;
  const int L = 10;
  const cv::Mat1f one = FusedSequenceMatrix(rows, Metric::kHamming, L, SequenceDirection::kForward,
                                            SequencePartial::kAhead, {}, 1, largest);
  for (const auto& [q, j] :
       std::vector<std::pair<int, int>>{{9, 9}, {100, 37}, {699, 0}, {3, 500}, {650, 651}})
    EXPECT_EQ(one(q, j), SequenceCellDistance(rows, q, rows, j, L, false)) << q << "," << j;
}

// The library's normalised matrix (Eq. 5) takes the one pass for binary rows: each cell is
// the two passes' cell over their largest value.
TEST(NormalizedDistanceMatrix, OnePassForBinaryRowsIsTheTwoPassMatrixNormalised) {
  const cv::Mat rows = RandomBytes(400, 32, 9);
  float max_distance = 0.0f;
  const cv::Mat1f m =
      NormalizedDistanceMatrix(rows, 8, SequenceDirection::kForward, {0, 150}, 2, &max_distance);
  cv::Mat1f two = TwoPasses(rows, Metric::kHamming, 8, SequenceDirection::kForward,
                            SequencePartial::kAhead, {0, 150});
  EXPECT_EQ(max_distance, NormalizeByMax(two));
  EXPECT_EQ(cv::norm(m, two, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace openable
