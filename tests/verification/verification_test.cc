// Geometric verification on scenes rendered in code from known poses, and temporal consistency
// on hand-made candidates. Expected inlier counts come from the true epipolar geometry of the
// poses (F = K^-T [t]x R K^-1), not from the code under test.
#include "OpenABLE/verification/verification.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "OpenABLE/base/error.h"
#include "matching/score.h"

namespace openable {
namespace {

constexpr double kFocal = 500, kCx = 320, kCy = 240;

struct Patch {
  cv::Vec3d point;    // world position of the patch's centre
  cv::Mat1b texture;  // 6 x 6 random grey levels
};

// A "room": textured square patches at depths 6 to 14 m in front of the first camera.
std::vector<Patch> Scene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(-5, 5), y(-3.5, 3.5), z(6, 14);
  cv::RNG textures(seed);  // not cv::randu, whose global generator other code advances
  std::vector<Patch> scene(220);
  for (Patch& p : scene) {
    p.point = {x(rng), y(rng), z(rng)};
    p.texture.create(6, 6);
    textures.fill(p.texture, cv::RNG::UNIFORM, 0, 256);
  }
  return scene;
}

// The scene seen by a camera at world-to-camera (R, t): each patch drawn as a square of 1.2 m
// side facing the camera, far ones first.
cv::Mat1b Render(const std::vector<Patch>& scene, const cv::Matx33d& r, const cv::Vec3d& t) {
  cv::Mat1b image(480, 640, static_cast<std::uint8_t>(128));
  std::vector<std::pair<double, int>> order;
  for (int i = 0; i < static_cast<int>(scene.size()); ++i) {
    const cv::Vec3d c = r * scene[i].point + t;
    if (c[2] > 1) order.emplace_back(-c[2], i);
  }
  std::sort(order.begin(), order.end());
  for (const auto& [negative_depth, i] : order) {
    const cv::Vec3d c = r * scene[i].point + t;
    const double u = kFocal * c[0] / c[2] + kCx, v = kFocal * c[1] / c[2] + kCy;
    const int side = static_cast<int>(std::lround(kFocal * 1.2 / c[2]));
    const cv::Rect box(static_cast<int>(std::lround(u)) - side / 2,
                       static_cast<int>(std::lround(v)) - side / 2, side, side);
    const cv::Rect inside = box & cv::Rect(0, 0, image.cols, image.rows);
    if (inside.area() == 0) continue;
    cv::Mat1b tile;
    cv::resize(scene[i].texture, tile, box.size(), 0, 0, cv::INTER_NEAREST);
    tile(cv::Rect(inside.tl() - box.tl(), inside.size())).copyTo(image(inside));
  }
  return image;
}

cv::Matx33d RotationY(double degrees) {
  const double a = degrees * CV_PI / 180, c = std::cos(a), s = std::sin(a);
  return {c, 0, s, 0, 1, 0, -s, 0, c};
}

// The true fundamental matrix mapping points of view 1 (identity pose) to epipolar lines of
// view 2 (world-to-camera R, t): F = K^-T [t]x R K^-1 (Hartley and Zisserman, eq. 9.2).
cv::Matx33d TrueFundamental(const cv::Matx33d& r, const cv::Vec3d& t) {
  const cv::Matx33d k(kFocal, 0, kCx, 0, kFocal, kCy, 0, 0, 1);
  const cv::Matx33d tx(0, -t[2], t[1], t[2], 0, -t[0], -t[1], t[0], 0);
  return k.inv().t() * tx * r * k.inv();
}

// Matches (after the ratio test, as PairVerifier makes them) within `threshold` pixels of their
// true epipolar lines in both views (the symmetric error OpenCV's RANSAC thresholds).
int TrueInliers(const FrameFeatures& a, const FrameFeatures& b, const cv::Matx33d& f, double ratio,
                double threshold) {
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(a.descriptors, b.descriptors, knn, 2);
  int inliers = 0;
  for (const auto& m : knn) {
    if (m.size() < 2 || !(m[0].distance < ratio * m[1].distance)) continue;
    const cv::Point2f p = a.points[m[0].queryIdx], q = b.points[m[0].trainIdx];
    const cv::Vec3d line2 = f * cv::Vec3d(p.x, p.y, 1), line1 = f.t() * cv::Vec3d(q.x, q.y, 1);
    const double d2 =
        std::abs(line2[0] * q.x + line2[1] * q.y + line2[2]) / std::hypot(line2[0], line2[1]);
    const double d1 =
        std::abs(line1[0] * p.x + line1[1] * p.y + line1[2]) / std::hypot(line1[0], line1[1]);
    inliers += std::max(d1, d2) <= threshold ? 1 : 0;
  }
  return inliers;
}

VerificationOptions Options() {
  VerificationOptions o;
  o.enabled = true;
  o.max_features = 1000;
  return o;
}

TEST(PairVerifier, RoomFromTwoKnownPosesIsVerifiedWithTheTrueInliers) {
  const std::vector<Patch> scene = Scene(7);
  const cv::Matx33d r = RotationY(3);
  const cv::Vec3d t(-0.6, 0.05, -0.4);
  const cv::Mat1b first = Render(scene, cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Mat1b second = Render(scene, r, t);
  const PairVerifier verifier(Options(), std::nullopt);
  const FrameFeatures a = verifier.Extract(first), b = verifier.Extract(second);
  ASSERT_GT(a.points.size(), 300u);
  const PairCheck check = verifier.Verify(a, b);
  const int expected =
      TrueInliers(a, b, TrueFundamental(r, t), Options().ratio, Options().ransac_threshold);
  ASSERT_GT(expected, 100);
  EXPECT_TRUE(check.verified);
  EXPECT_EQ(check.model, GeometricModel::kFundamental);
  // RANSAC's model is estimated from noisy points: its inliers lie within a few percent of the
  // matches the true geometry accepts.
  EXPECT_NEAR(check.inliers, expected, 0.08 * expected) << check.matches << " matches";
}

TEST(PairVerifier, CalibratedRoomUsesTheEssentialMatrix) {
  const std::vector<Patch> scene = Scene(7);
  const cv::Matx33d r = RotationY(3);
  const cv::Vec3d t(-0.6, 0.05, -0.4);
  const PairVerifier verifier(Options(), CameraIntrinsics{kFocal, kFocal, kCx, kCy});
  const FrameFeatures a = verifier.Extract(Render(scene, cv::Matx33d::eye(), {0, 0, 0}));
  const FrameFeatures b = verifier.Extract(Render(scene, r, t));
  const PairCheck check = verifier.Verify(a, b);
  const int expected =
      TrueInliers(a, b, TrueFundamental(r, t), Options().ratio, Options().ransac_threshold);
  EXPECT_TRUE(check.verified);
  EXPECT_EQ(check.model, GeometricModel::kEssential);
  EXPECT_NEAR(check.inliers, expected, 0.08 * expected);
}

TEST(PairVerifier, DifferentSceneIsRejected) {
  const PairVerifier verifier(Options(), std::nullopt);
  const FrameFeatures a = verifier.Extract(Render(Scene(7), cv::Matx33d::eye(), {0, 0, 0}));
  const FrameFeatures b = verifier.Extract(Render(Scene(8), cv::Matx33d::eye(), {0, 0, 0}));
  const PairCheck check = verifier.Verify(a, b);
  EXPECT_FALSE(check.verified);
  EXPECT_LT(check.inliers, Options().min_inliers);
}

TEST(PairVerifier, IdenticalImagesAreVerifiedThroughTheHomography) {
  const PairVerifier verifier(Options(), std::nullopt);
  const FrameFeatures a = verifier.Extract(Render(Scene(7), cv::Matx33d::eye(), {0, 0, 0}));
  const PairCheck check = verifier.Verify(a, a);
  EXPECT_TRUE(check.verified);
  EXPECT_EQ(check.model, GeometricModel::kHomography);
  // Every match is exact: each feature's nearest neighbour is itself, and the ratio test
  // keeps it unless another feature has the very same descriptor.
  EXPECT_EQ(check.inliers, check.matches);
  EXPECT_GT(check.matches, 0.9 * static_cast<double>(a.points.size()));
}

TEST(PairVerifier, PureRotationIsVerifiedThroughTheHomography) {
  const std::vector<Patch> scene = Scene(7);
  const PairVerifier verifier(Options(), std::nullopt);
  const FrameFeatures a = verifier.Extract(Render(scene, cv::Matx33d::eye(), {0, 0, 0}));
  // A camera turning on the spot sees the first image mapped by H = K R K^-1.
  const cv::Matx33d k(kFocal, 0, kCx, 0, kFocal, kCy, 0, 0, 1);
  cv::Mat1b turned;
  cv::warpPerspective(Render(scene, cv::Matx33d::eye(), {0, 0, 0}), turned,
                      cv::Mat(k * RotationY(4) * k.inv()), cv::Size(640, 480), cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(128));
  const FrameFeatures b = verifier.Extract(turned);
  const PairCheck check = verifier.Verify(a, b);
  EXPECT_TRUE(check.verified);
  EXPECT_EQ(check.model, GeometricModel::kHomography)
      << check.matches << " matches, " << check.inliers << " inliers";
}

TEST(PairVerifier, TooFewMatchesSkipRansac) {
  VerificationOptions o = Options();
  o.min_inliers = 100000;
  const PairVerifier verifier(o, std::nullopt);
  const FrameFeatures a = verifier.Extract(Render(Scene(7), cv::Matx33d::eye(), {0, 0, 0}));
  const PairCheck check = verifier.Verify(a, a);
  EXPECT_FALSE(check.verified);
  EXPECT_EQ(check.model, GeometricModel::kNone);
  EXPECT_EQ(check.inliers, 0);
}

// Found by tests/fuzz/map_fuzzer.cc: with Verification_min_inliers below 7, a candidate with
// that many to 6 matches reached cv::findFundamentalMat, whose USAC sampler throws a
// cv::Exception for fewer points than its 7-point sample. Every count from the smallest
// min_inliers up is checked here, uncalibrated and calibrated; below 8 matches only the
// homography is fitted without a calibration.
TEST(PairVerifier, FewMatchesAboveTheSmallestMinInliersAreChecked) {
  VerificationOptions o = Options();
  o.min_inliers = 5;
  const PairVerifier plain(o, std::nullopt);
  const PairVerifier calibrated(o, CameraIntrinsics{kFocal, kFocal, kCx, kCy});
  cv::RNG rng(11);
  for (int n = 5; n <= 9; ++n) {
    FrameFeatures f;
    f.descriptors.create(n, 32, CV_8U);
    rng.fill(f.descriptors, cv::RNG::UNIFORM, 0, 256);  // distinct rows: each matches itself
    for (int i = 0; i < n; ++i)
      f.points.emplace_back(rng.uniform(0.f, 640.f), rng.uniform(0.f, 480.f));
    PairCheck check;
    ASSERT_NO_THROW(check = plain.Verify(f, f)) << n << " matches";
    EXPECT_EQ(check.matches, n);
    if (n < 8) {
      EXPECT_NE(check.model, GeometricModel::kFundamental) << n;
    }
    ASSERT_NO_THROW(calibrated.Verify(f, f)) << n << " matches, calibrated";
  }
}

TEST(VerificationOptions, RefusesValuesOutOfRangeNamingTheKey) {
  VerificationOptions o;
  o.max_features = 0;
  EXPECT_THROW(
      {
        try {
          o.Check();
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("Verification_max_features"), std::string::npos);
          throw;
        }
      },
      InputError);
  o = VerificationOptions();
  o.min_inliers = 4;
  EXPECT_THROW(o.Check(), InputError);
  o = VerificationOptions();
  o.consistency = -1;
  EXPECT_THROW(o.Check(), InputError);
}

// ---- Temporal consistency -------------------------------------------------------------------

// A query with candidates given as (reference, geometrically verified).
QueryVerification Query(int query, const std::vector<std::pair<int, bool>>& candidates) {
  QueryVerification q;
  q.query = query;
  for (const auto& [reference, verified] : candidates) {
    VerifiedCandidate c;
    c.reference = reference;
    c.check.verified = verified;
    c.check.inliers = verified ? 50 : 0;
    q.candidates.push_back(c);
  }
  return q;
}

TEST(TemporalConsistency, HandMadeSequence) {
  // Queries 200..207: a loop along references 50, 51, 53 (within 2 of each other), broken by
  // an unverified query, a jump to another place, and a query that is not consecutive.
  std::vector<QueryVerification> queries = {
      Query(200, {{50, true}, {90, false}}),  // streak 1
      Query(201, {{90, true}, {51, true}}),   // 90: 1 (no neighbour), 51: 2
      Query(202, {{53, true}}),               // |53 - 51| = 2 <= 2: 3
      Query(203, {{56, true}}),               // |56 - 53| = 3 > 2: 1
      Query(204, {{57, false}}),              // not verified: 0
      Query(205, {{58, true}}),               // previous had none verified: 1
      Query(207, {{59, true}}),               // 206 missing: not consecutive, 1
      Query(208, {{60, true}, {61, true}}),   // both neighbour 59: 2 each
  };
  ApplyTemporalConsistency(queries, /*consistency=*/1, /*tolerance=*/2);
  const std::vector<std::vector<int>> streaks = {{1, 0}, {1, 2}, {3}, {1}, {0}, {1}, {1}, {2, 2}};
  const std::vector<int> answers = {-1, 1, 0, -1, -1, -1, -1, 0};
  for (std::size_t i = 0; i < queries.size(); ++i) {
    for (std::size_t c = 0; c < queries[i].candidates.size(); ++c) {
      EXPECT_EQ(queries[i].candidates[c].streak, streaks[i][c]) << "query " << queries[i].query;
      EXPECT_EQ(queries[i].candidates[c].accepted, streaks[i][c] > 1);
    }
    EXPECT_EQ(queries[i].answer, answers[i]) << "query " << queries[i].query;
  }
  // Consistency 0: every verified candidate is accepted; the answer is the best-ranked one.
  ApplyTemporalConsistency(queries, 0, 2);
  EXPECT_EQ(queries[0].answer, 0);
  EXPECT_EQ(queries[1].answer, 0);
  EXPECT_EQ(queries[4].answer, -1);
  // Consistency 2: only the third of a run of three.
  ApplyTemporalConsistency(queries, 2, 2);
  EXPECT_EQ(queries[1].answer, -1);
  EXPECT_EQ(queries[2].answer, 0);
}

TEST(DistinctBest, TakesTheBestPlacesApartByMoreThanTheWindow) {
  // (distance, frame): the best at 40, its neighbours 41 and 38 are the same place; next 10,
  // then 52 (12 from 40), then 90; a non-finite cell is never taken.
  const std::vector<std::pair<float, int>> cells = {{0.2f, 40},
                                                    {0.21f, 41},
                                                    {0.25f, 38},
                                                    {0.3f, 10},
                                                    {0.35f, 52},
                                                    {0.5f, 90},
                                                    {std::numeric_limits<float>::infinity(), 70},
                                                    {0.3f, 9}};
  const std::vector<std::size_t> best = DistinctBest(cells, 4, 10);
  ASSERT_EQ(best.size(), 4u);
  // Ties (0.3 at 10 and at 9): the lower frame first, and 10 is then its neighbour.
  EXPECT_EQ(cells[best[0]].second, 40);
  EXPECT_EQ(cells[best[1]].second, 9);
  EXPECT_EQ(cells[best[2]].second, 52);
  EXPECT_EQ(cells[best[3]].second, 90);
  EXPECT_EQ(DistinctBest(cells, 10, 1000).size(), 1u);
  EXPECT_TRUE(DistinctBest({}, 3, 5).empty());
}

}  // namespace
}  // namespace openable
