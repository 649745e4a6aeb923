#include "OpenABLE/snaps/discounted.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace openable::snaps {
namespace {

// A drifting line of poses: frame i at (i, 0.1 i, 0.01 i^2), rotated by i degrees about y.
Trajectory Line(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.linear() = Eigen::AngleAxisd(i * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
    p.translation() = Eigen::Vector3d(i, 0.1 * i, 0.01 * i * i);
    t.poses.push_back(p);
    t.frame_ids.push_back(i);
  }
  return t;
}

// Eq. 6 as written in the paper, read as an increment, gamma clamped at 0.
double Gamma(int s_prime, int alpha) {
  return std::max(0.0, 1 - 1 / std::exp(3 - alpha * 0.01 * s_prime));
}

TEST(Discounted, GammaAtZeroAndClamp) {
  for (const int alpha : {1, 2, 7}) EXPECT_DOUBLE_EQ(DiscountGamma(0, alpha), 1 - std::exp(-3.0));
  EXPECT_GT(DiscountGamma(149, 2), 0.0);
  EXPECT_NEAR(DiscountGamma(150, 2), 0.0, 1e-15);  // 3 - 0.01 * 2 * 150 = 0
  EXPECT_EQ(DiscountGamma(200, 2), 0.0);           // would be 1 - e = -1.72
  EXPECT_EQ(DiscountGamma(1000, 1), 0.0);
  EXPECT_LT(DiscountGamma(50, 3), DiscountGamma(50, 1));  // more loops, faster decay
  EXPECT_THROW(DiscountGamma(0, 0), std::invalid_argument);
}

TEST(Discounted, OneLoopAsTheFormula) {
  const Trajectory before = Line(60);
  Trajectory t = before;
  const int n = 40, ref = 5, alpha = 3, k = 25;
  const double q = 0.8;
  const Eigen::Vector3d delta = before.poses[ref].translation() - before.poses[n].translation();
  const Eigen::Vector3d shift = ApplyDiscountedUpdate(t, n, ref, q, alpha, k);
  EXPECT_TRUE(shift.isApprox(q * (1 - std::exp(-3.0)) * delta, 1e-14));
  for (int s = 0; s < 60; ++s) {
    Eigen::Vector3d expected = before.poses[s].translation();
    if (s >= n - k && s <= n) expected += q * Gamma(n - s, alpha) * delta;
    if (s > n) expected += q * Gamma(0, alpha) * delta;  // later frames follow frame N
    EXPECT_LT((t.poses[s].translation() - expected).norm(), 1e-12) << s;
    EXPECT_TRUE(t.poses[s].linear().isApprox(before.poses[s].linear(), 0)) << s;  // untouched
  }
  EXPECT_EQ(t.poses[n - k - 1].translation(), before.poses[n - k - 1].translation());
  EXPECT_NE(t.poses[n - k].translation(), before.poses[n - k].translation());
}

TEST(Discounted, ClampedFramesDoNotMove) {
  const Trajectory before = Line(300);
  Trajectory t = before;
  // alpha = 10: gamma = 0 from s' = 30 on, so with K = 200 frames 80..250 (s' >= 30) stay.
  ApplyDiscountedUpdate(t, 280, 0, 1.0, 10, 200);
  for (int s = 80; s <= 250; ++s)
    EXPECT_EQ(t.poses[s].translation(), before.poses[s].translation()) << s;
  EXPECT_NE(t.poses[251].translation(), before.poses[251].translation());
}

TEST(Discounted, KBeyondTheStart) {
  Trajectory t = Line(20);
  const Trajectory before = t;
  ApplyDiscountedUpdate(t, 12, 1, 1.0, 1, 100);  // s from max(0, 12 - 100) = 0
  const Eigen::Vector3d delta = before.poses[1].translation() - before.poses[12].translation();
  EXPECT_LT(
      (t.poses[0].translation() - before.poses[0].translation() - Gamma(12, 1) * delta).norm(),
      1e-12);
  EXPECT_THROW(ApplyDiscountedUpdate(t, 20, 1, 1.0, 1, 5), std::invalid_argument);
  EXPECT_THROW(ApplyDiscountedUpdate(t, 5, 5, 1.0, 1, 5), std::invalid_argument);
}

TEST(Discounted, CorrectInQueryOrderWithPause) {
  const Trajectory input = Line(100);
  const std::vector<LoopPair> loops = {{70, 3, 0.9}, {50, 10, 0.8}, {55, 12, 1.0}, {90, 20, 0.7}};
  DiscountOptions options;
  options.discount_length = 30;
  options.pause = 10;
  const Trajectory out = CorrectDiscounted(input, loops, options);
  // By hand: 50 closes (alpha 1), 55 is within the pause (55 - 50 <= 10), 70 (alpha 2),
  // 90 (alpha 3), each from the positions the earlier ones left.
  Trajectory expected = input;
  ApplyDiscountedUpdate(expected, 50, 10, 0.8, 1, 30);
  ApplyDiscountedUpdate(expected, 70, 3, 0.9, 2, 30);
  ApplyDiscountedUpdate(expected, 90, 20, 0.7, 3, 30);
  for (int i = 0; i < 100; ++i)
    EXPECT_LT((out.poses[i].translation() - expected.poses[i].translation()).norm(), 1e-12) << i;
  const std::vector<LoopPair> closed = ClosedLoops(loops, 10);
  ASSERT_EQ(closed.size(), 3u);
  EXPECT_EQ(closed[0].query, 50);
  EXPECT_EQ(closed[1].query, 70);
  EXPECT_EQ(closed[2].query, 90);
  EXPECT_EQ(ClosedLoops(loops, 0).size(), 4u);
  EXPECT_THROW(CorrectDiscounted(input, {{100, 3, 1}}, options), std::invalid_argument);
  EXPECT_THROW(CorrectDiscounted(input, {{30, 30, 1}}, options), std::invalid_argument);
}

}  // namespace
}  // namespace openable::snaps
