#include "OpenABLE/snaps/loop_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>

namespace openable::snaps {
namespace {

// KITTI-like pose: position (x, 0, z), heading `yaw_deg` about the (downward) y axis.
Eigen::Isometry3d Pose(double x, double z, double yaw_deg = 0) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, 0, z);
  return p;
}

cv::Mat1b Noise(int seed) {
  cv::Mat1b m(16, 24);
  cv::RNG rng(static_cast<uint64_t>(seed) * 7919 + 1);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

SearchOptions Options() {
  SearchOptions o;
  o.window = 8;
  o.radius = 3;
  o.frame_distance = 20;
  o.attempts = 10;
  o.discount.pause = 5;
  return o;
}

// Frames 0..39 along z (frame i at z = i, heading +z, its own random thumbnail), then frames
// 40..(first - 1) far away.
void Drive(LoopSearch& search, int first) {
  for (int i = 0; i < 40; ++i) ASSERT_FALSE(search.Step(i, Pose(0, i), Noise(i)));
  for (int i = 40; i < first; ++i) ASSERT_FALSE(search.Step(i, Pose(500, i), Noise(i)));
}

// A search with Options() but for what `change` sets, driven through frames 0..59 (Drive).
LoopSearch Driven(const std::function<void(SearchOptions&)>& change = [](SearchOptions&) {}) {
  SearchOptions o = Options();
  change(o);
  LoopSearch search(o);
  Drive(search, 60);
  return search;
}

TEST(LoopSearch, FindsTheRevisitedFrame) {
  LoopSearch search = Driven();
  const auto loop = search.Step(60, Pose(0, 10), Noise(10));
  ASSERT_TRUE(loop);
  EXPECT_EQ(loop->query, 60);
  EXPECT_EQ(loop->reference, 10);
  EXPECT_EQ(loop->similarity, 1.0);
  EXPECT_EQ(search.last_pinned(), 60);
  EXPECT_TRUE(search.records().back().loop);
  EXPECT_EQ(search.records().back().candidates, 7);  // frames 7..13 within 3 m
  EXPECT_EQ(search.records()[59].candidates, 0);
}

TEST(LoopSearch, NotWithinFrameDistance) {
  for (const int m : {20, 15}) {
    SearchOptions o = Options();
    o.frame_distance = m;
    LoopSearch search(o);
    for (int i = 0; i < 25; ++i) ASSERT_FALSE(search.Step(i, Pose(0, i), Noise(i)));
    // Frame 25 back at frame 10 (25 - 10 = 15 frames later).
    EXPECT_EQ(search.Step(25, Pose(0, 10), Noise(10)).has_value(), m <= 15) << "M = " << m;
  }
}

TEST(LoopSearch, YawLimit) {
  for (const double yaw : {15.0, -12.0, 8.0, -9.5}) {
    LoopSearch search = Driven();
    EXPECT_EQ(search.Step(60, Pose(0, 10, yaw), Noise(10)).has_value(), std::abs(yaw) <= 10) << yaw;
  }
}

TEST(LoopSearch, InterFramePause) {
  LoopSearch search = Driven();
  ASSERT_TRUE(search.Step(60, Pose(0, 10), Noise(10)));
  for (int i = 61; i <= 65; ++i) {  // i - 60 <= pause = 5
    EXPECT_FALSE(search.Step(i, Pose(0, i - 50), Noise(i - 50))) << i;
    EXPECT_TRUE(search.records().back().paused);
  }
  const auto loop = search.Step(66, Pose(0, 16), Noise(16));
  ASSERT_TRUE(loop);
  EXPECT_EQ(loop->reference, 16);
  EXPECT_EQ(search.loops_closed(), 2);
}

TEST(LoopSearch, Radius) {
  for (const double radius : {3.0, 5.0}) {
    LoopSearch search = Driven([&](SearchOptions& o) { o.radius = radius; });
    // 4 m beside frame 10.
    EXPECT_EQ(search.Step(60, Pose(4, 10), Noise(10)).has_value(), radius >= 4) << radius;
  }
}

TEST(LoopSearch, AttemptsNearestFirst) {
  // At z = 12 the candidates by distance are 12, 11, 13, 10, ...: frame 10 is the 4th.
  for (const int attempts : {3, 4}) {
    LoopSearch search = Driven([&](SearchOptions& o) { o.attempts = attempts; });
    const auto loop = search.Step(60, Pose(0, 12), Noise(10));
    EXPECT_EQ(loop.has_value(), attempts >= 4) << attempts;
    EXPECT_EQ(search.records().back().candidates, attempts);
  }
}

TEST(LoopSearch, BestOrFirst) {
  for (const bool first : {false, true}) {
    SearchOptions o = Options();
    o.accept_first = first;
    LoopSearch search(o);
    for (int i = 0; i < 40; ++i) {
      cv::Mat1b t = Noise(i);
      if (i == 11) t = Noise(10) + 5;  // similar to frame 10, not identical
      ASSERT_FALSE(search.Step(i, Pose(0, i), t));
    }
    // At z = 11, frame 11 (Q < 1) comes before frame 10 (Q = 1).
    const auto loop = search.Step(40, Pose(0, 11), Noise(10));
    ASSERT_TRUE(loop);
    EXPECT_EQ(loop->reference, first ? 11 : 10);
    EXPECT_EQ(loop->similarity == 1.0, !first);
    EXPECT_GE(loop->similarity, 0.75);
  }
}

TEST(LoopSearch, MinimumSimilarity) {
  for (const double min : {0.75, 0.99}) {
    LoopSearch search = Driven([&](SearchOptions& o) { o.min_similarity = min; });
    cv::Mat1b t = Noise(10).clone();
    cv::Mat1b noise(t.size());
    cv::RNG(3).fill(noise, cv::RNG::UNIFORM, 0, 30);
    t = t / 2 + 60 + noise;  // similar, Q between 0.75 and 0.99
    const auto loop = search.Step(60, Pose(0, 10), t);
    EXPECT_EQ(loop.has_value(), min < 0.9) << min;
  }
}

TEST(LoopSearch, WrongIndexOrThumbnail) {
  LoopSearch search(Options());
  search.Step(0, Pose(0, 0), Noise(0));
  EXPECT_THROW(search.Step(2, Pose(0, 0), Noise(1)), std::invalid_argument);
  EXPECT_THROW(search.Step(1, Pose(0, 0), cv::Mat1b(5, 5)), std::invalid_argument);
}

TEST(LoopSearch, YawDifference) {
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  EXPECT_NEAR(YawDifferenceDeg(Pose(0, 0, 30), Pose(0, 0, -20), y), 50, 1e-9);
  EXPECT_NEAR(YawDifferenceDeg(Pose(0, 0, 170), Pose(0, 0, -170), y), 20, 1e-9);
  // Pitch does not count.
  Eigen::Isometry3d pitched = Pose(0, 0, 5);
  pitched.linear() = pitched.linear() * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(YawDifferenceDeg(pitched, Pose(0, 0, 0), y), 5, 1e-9);
}

TEST(OnlineSnaps, CorrectsAndLaterFramesFollow) {
  SearchOptions o = Options();
  o.discount.discount_length = 30;
  OnlineSnaps snaps(o);
  // Odometry drifts by +0.05 m in x per frame after frame 40.
  auto vo = [](int i, double z) { return Pose(i > 40 ? 0.05 * (i - 40) : 0, z); };
  for (int i = 0; i < 40; ++i) ASSERT_FALSE(snaps.Step(vo(i, i), Noise(i)));
  for (int i = 40; i < 60; ++i) ASSERT_FALSE(snaps.Step(vo(i, 100 + i), Noise(i)));
  const Eigen::Vector3d p60 = vo(60, 10).translation();  // 1 m off in x
  const auto loop = snaps.Step(vo(60, 10), Noise(10));
  ASSERT_TRUE(loop);
  ASSERT_EQ(loop->reference, 10);
  const Eigen::Vector3d delta = Eigen::Vector3d(0, 0, 10) - p60;
  const double g0 = 1 - std::exp(-3.0);
  EXPECT_LT((snaps.corrected()[60].translation() - (p60 + g0 * delta)).norm(), 1e-12);
  const double g10 = 1 - 1 / std::exp(3 - 0.01 * 10);
  EXPECT_LT(
      (snaps.corrected()[50].translation() - (vo(50, 150).translation() + g10 * delta)).norm(),
      1e-12);
  EXPECT_EQ(snaps.corrected()[29].translation(), vo(29, 29).translation());  // s < N - K
  snaps.Step(vo(61, 11), Noise(11));
  EXPECT_LT((snaps.corrected()[61].translation() - (vo(61, 11).translation() + g0 * delta)).norm(),
            1e-12);
  EXPECT_EQ(snaps.correction_seconds().size(), 1u);
}

TEST(Latency, Summarize) {
  const LatencyStats s = Summarize({5, 1, 4, 2, 3});
  EXPECT_EQ(s.count, 5);
  EXPECT_DOUBLE_EQ(s.mean, 3);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.q1, 2);
  EXPECT_DOUBLE_EQ(s.median, 3);
  EXPECT_DOUBLE_EQ(s.q3, 4);
  EXPECT_DOUBLE_EQ(s.max, 5);
  EXPECT_DOUBLE_EQ(Summarize({1, 2}).median, 1.5);
  EXPECT_EQ(Summarize({}).count, 0);
}

}  // namespace
}  // namespace openable::snaps
