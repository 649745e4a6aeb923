// Trajectory files, association with a ground truth and absolute trajectory error, on small
// files written here with values computed by hand.
#include "OpenABLE/snaps/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"

namespace openable::snaps {
namespace {

using namespace openable::testing;  // NOLINT: TempDir, WriteBytes, Q, ExpectInputError,
                                    // DatasetsDir

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = TempDir() + "/" + name;
  WriteBytes(path, text);
  return path;
}

// Yaw of 90 degrees about the camera's y axis (KITTI's vertical): x -> -z, z -> x.
Eigen::Matrix3d Yaw90() {
  Eigen::Matrix3d r;
  r << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  return r;
}

Eigen::Isometry3d RandomPose(std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = q.toRotationMatrix();
  t.translation() = Eigen::Vector3d(100 * g(rng), g(rng), 1000 * g(rng));
  return t;
}

TEST(ReadTrajectory, KittiLinesArePosesOfConsecutiveFrames) {
  const std::string path = Write("k.txt",
                                 "1 0 0 0 0 1 0 0 0 0 1 0\n"
                                 "0 0 1 1.5 0 1 0 -2 -1 0 0 3.25\n"
                                 "\n");
  const Trajectory t = ReadTrajectory(path, TrajectoryFormat::kKitti);
  ASSERT_EQ(t.Size(), 2);
  EXPECT_EQ(t.frame_ids, (std::vector<long>{0, 1}));
  EXPECT_TRUE(t.timestamps.empty());
  EXPECT_TRUE(t.poses[0].matrix().isIdentity(0));
  EXPECT_EQ(t.poses[1].linear(), Yaw90());
  EXPECT_EQ(t.poses[1].translation(), Eigen::Vector3d(1.5, -2, 3.25));
  // The camera's forward axis (z) points along world +x after the yaw.
  EXPECT_EQ(t.poses[1].linear() * Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
}

TEST(ReadTrajectory, KittiWithIdKeepsFrameNumbers) {
  const std::string path = Write("kid.txt",
                                 "0 1 0 0 0 0 1 0 0 0 0 1 0\n"
                                 "7 1 0 0 1 0 1 0 2 0 0 1 3\n"
                                 "12 1 0 0 4 0 1 0 5 0 0 1 6\n");
  const Trajectory t = ReadTrajectory(path, TrajectoryFormat::kKittiWithId);
  EXPECT_EQ(t.frame_ids, (std::vector<long>{0, 7, 12}));
  EXPECT_EQ(t.poses[2].translation(), Eigen::Vector3d(4, 5, 6));
}

TEST(ReadTrajectory, WorldToCameraIsInverted) {
  // World-to-camera [R | t] with R the 90-degree yaw, t = (1, 2, 3): camera-to-world is
  // [R^T | -R^T t] = R^T and (3, -2, -1) by hand.
  const std::string path = Write("w2c.txt", "4 0 0 1 1 0 1 0 2 -1 0 0 3\n");
  const Trajectory t = ReadTrajectory(path, TrajectoryFormat::kKittiWithId, true);
  EXPECT_TRUE(t.world_to_camera);
  EXPECT_EQ(t.poses[0].linear(), Yaw90().transpose());
  EXPECT_EQ(t.poses[0].translation(), Eigen::Vector3d(3, -2, -1));
  Eigen::Matrix4d file = Eigen::Matrix4d::Identity();
  file.topLeftCorner<3, 3>() = Yaw90();
  file.topRightCorner<3, 1>() = Eigen::Vector3d(1, 2, 3);
  EXPECT_TRUE(t.poses[0].matrix().isApprox(file.inverse(), 1e-15));
}

TEST(ReadTrajectory, TumQuaternionAndTimestamps) {
  // q = (x, y, z, w) = (0, 0, sin 45, cos 45): 90 degrees about z, x -> y.
  const std::string path = Write("t.txt",
                                 "# timestamp tx ty tz qx qy qz qw\n"
                                 "1.5 1 2 3 0 0 0.70710678118654757 0.70710678118654757\n"
                                 "1.75 0 0 0 0 0 0 1\n");
  const Trajectory t = ReadTrajectory(path, TrajectoryFormat::kTum);
  ASSERT_EQ(t.Size(), 2);
  EXPECT_EQ(t.timestamps, (std::vector<double>{1.5, 1.75}));
  EXPECT_EQ(t.frame_ids, (std::vector<long>{0, 1}));
  Eigen::Matrix3d rz;
  rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(t.poses[0].linear().isApprox(rz, 1e-15));
  EXPECT_EQ(t.poses[0].translation(), Eigen::Vector3d(1, 2, 3));
}

TEST(ReadTrajectory, NearlyOrthonormalRotationIsRepaired) {
  // Entries off by 2e-4 (within 1e-3): accepted and replaced by the nearest rotation.
  const std::string path = Write("near.txt", "1.0002 0 0 0 0 0.9999 0 0 0 0 1 0\n");
  const Trajectory t = ReadTrajectory(path, TrajectoryFormat::kKitti);
  const Eigen::Matrix3d& r = t.poses[0].linear();
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r.determinant(), 1, 1e-14);
  // ... and it writes back to itself.
  const std::string again = Write("near2.txt", EncodeTrajectory(t));
  EXPECT_EQ(ReadTrajectory(again, TrajectoryFormat::kKitti).poses[0].matrix(), t.poses[0].matrix());
}

TEST(EncodeTrajectory, KittiRoundTripIsExact) {
  std::mt19937 rng(7);
  for (const TrajectoryFormat format : {TrajectoryFormat::kKitti, TrajectoryFormat::kKittiWithId}) {
    Trajectory t;
    t.format = format;
    for (int i = 0; i < 50; ++i) {
      t.poses.push_back(RandomPose(rng));
      t.frame_ids.push_back(format == TrajectoryFormat::kKitti ? i : 3 * i + 1);
    }
    const std::string path = Write("rt.txt", EncodeTrajectory(t));
    const Trajectory back = ReadTrajectory(path, format);
    ASSERT_EQ(back.Size(), t.Size());
    EXPECT_EQ(back.frame_ids, t.frame_ids);
    for (int i = 0; i < t.Size(); ++i) {
      EXPECT_EQ(back.poses[i].matrix(), t.poses[i].matrix()) << TrajectoryFormatName(format) << i;
    }
  }
}

TEST(EncodeTrajectory, TumAndWorldToCameraRoundTripToRounding) {
  // A quaternion and an inversion are recomputed on writing: equal to a few ulps, and the text
  // read back a second time writes the same text.
  std::mt19937 rng(11);
  Trajectory tum;
  tum.format = TrajectoryFormat::kTum;
  Trajectory w2c;
  w2c.format = TrajectoryFormat::kKittiWithId;
  w2c.world_to_camera = true;
  for (int i = 0; i < 50; ++i) {
    tum.poses.push_back(RandomPose(rng));
    tum.frame_ids.push_back(i);
    tum.timestamps.push_back(1e9 + 0.1 * i + 1e-7);
    w2c.poses.push_back(RandomPose(rng));
    w2c.frame_ids.push_back(2 * i);
  }
  for (const Trajectory* t : {&tum, &w2c}) {
    const Trajectory back =
        ReadTrajectory(Write("a.txt", EncodeTrajectory(*t)), t->format, t->world_to_camera);
    EXPECT_EQ(back.timestamps, t->timestamps);
    EXPECT_EQ(back.frame_ids, t->frame_ids);
    for (int i = 0; i < t->Size(); ++i) {
      EXPECT_LT((back.poses[i].linear() - t->poses[i].linear()).cwiseAbs().maxCoeff(), 1e-15);
      EXPECT_LT((back.poses[i].translation() - t->poses[i].translation()).norm(),
                1e-15 * (1 + t->poses[i].translation().norm()) * 10);
    }
  }
}

TEST(ReadTrajectory, ErrorsNameFileLineValueAndExpectation) {
  const auto read = [](const std::string& path, TrajectoryFormat format) {
    return [path, format] { ReadTrajectory(path, format); };
  };
  const std::string ok = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  std::string p = Write("count.txt", ok + ok + "1 0 0 0 0 1 0 0 0 0 1\n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti), {Q(p) + ":3", "11 numbers", "expected 12"});
  p = Write("count_id.txt", ok);
  ExpectInputError(read(p, TrajectoryFormat::kKittiWithId),
                   {Q(p) + ":1", "12 numbers", "expected 13",
                    "12 numbers without a frame number are the format kitti"});
  // A file of keyframes (a frame number, then the 12 numbers) read as kitti names kitti-id.
  p = Write("keyframes.txt", "0 " + ok + "5 " + ok);
  ExpectInputError(read(p, TrajectoryFormat::kKitti),
                   {Q(p) + ":1", "13 numbers", "expected 12",
                    "a frame number then 12 numbers is the format kitti-id"});
  p = Write("nan_word.txt", ok + "1 0 0 x1 0 1 0 0 0 0 1 0\n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti),
                   {Q(p) + ":2", "\"x1\"", "column 4", "not a number"});
  p = Write("nan.txt", "1 0 0 nan 0 1 0 0 0 0 1 0\n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti), {Q(p) + ":1", "\"nan\"", "not finite"});
  p = Write("inf.txt", "1 0 0 0 0 1 0 0 0 0 1 -inf\n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti), {Q(p) + ":1", "\"-inf\"", "not finite"});
  p = Write("scaled.txt", ok + ok + ok + "2 0 0 0 0 2 0 0 0 0 2 0\n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti),
                   {Q(p) + ":4", "not a rotation", "max |R^T R - I| = 3", "0.001"});
  p = Write("mirror.txt", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti), {Q(p) + ":1", "det = -1", "+1"});
  p = Write("ids.txt", "3 " + ok + "3 " + ok);
  ExpectInputError(read(p, TrajectoryFormat::kKittiWithId),
                   {Q(p) + ":2", "frame 3 after frame 3", "strictly increasing"});
  p = Write("id_word.txt", "a " + ok);
  ExpectInputError(read(p, TrajectoryFormat::kKittiWithId),
                   {Q(p) + ":1", "\"a\"", "not a frame number"});
  p = Write("id_negative.txt", "-2 " + ok);
  ExpectInputError(read(p, TrajectoryFormat::kKittiWithId), {Q(p) + ":1", "\"-2\"", "integer"});
  p = Write("empty.txt", "\n  \n");
  ExpectInputError(read(p, TrajectoryFormat::kKitti), {Q(p), "no pose", "12 numbers"});
  p = TempDir() + "/missing.txt";
  ExpectInputError(read(p, TrajectoryFormat::kKitti), {Q(p), "does not exist"});
  p = Write("quat.txt", "0 1 2 3 0 0 0 1\n1 1 2 3 0 0 0.5 0.5\n");
  ExpectInputError(read(p, TrajectoryFormat::kTum),
                   {Q(p) + ":2", "norm 0.70710678118654", "unit quaternion"});
  p = Write("time.txt", "# t\n0.5 1 2 3 0 0 0 1\n0.25 1 2 3 0 0 0 1\n");
  ExpectInputError(read(p, TrajectoryFormat::kTum),
                   {Q(p) + ":3", "timestamp 0.25 after 0.5", "strictly increasing"});
  ExpectInputError([] { ParseTrajectoryFormat("euroc", "Trajectory_format"); },
                   {"Trajectory_format", "\"euroc\"", "kitti", "kitti-id", "tum"});
  EXPECT_EQ(ParseTrajectoryFormat("KITTI-id", "k"), TrajectoryFormat::kKittiWithId);
}

Trajectory Line(TrajectoryFormat format, const std::vector<long>& ids,
                const std::vector<double>& times = {}) {
  Trajectory t;
  t.format = format;
  t.frame_ids = ids;
  t.timestamps = times;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation() = Eigen::Vector3d(static_cast<double>(ids[i]), 0, 0);
    t.poses.push_back(p);
  }
  return t;
}

TEST(AssociateWithTruth, ByFrameId) {
  const Trajectory truth = Line(TrajectoryFormat::kKitti, {0, 1, 2, 3, 4, 5});
  const Trajectory estimate = Line(TrajectoryFormat::kKittiWithId, {0, 2, 5});
  EXPECT_EQ(AssociateWithTruth(estimate, truth, 0, "k"), (std::vector<int>{0, 2, 5}));
  const Trajectory beyond = Line(TrajectoryFormat::kKittiWithId, {0, 2, 7, 9});
  ExpectInputError([&] { AssociateWithTruth(beyond, truth, 0, "Ground_truth"); },
                   {"Ground_truth", "frame 7", "pose 2", "0 .. 5"});
  // A ground truth with gaps: frame 3 missing.
  const Trajectory gappy = Line(TrajectoryFormat::kKittiWithId, {0, 2, 4});
  ExpectInputError(
      [&] {
        AssociateWithTruth(Line(TrajectoryFormat::kKitti, {0, 1, 2, 3}), gappy, 0, "gt");
      },
      {"gt", "frame 1", "0 .. 4"});
}

TEST(AssociateWithTruth, ByNearestTimestampWithinTolerance) {
  const Trajectory truth =
      Line(TrajectoryFormat::kTum, {0, 1, 2, 3, 4, 5}, {0.0, 0.1, 0.2, 0.3, 0.4, 0.5});
  const Trajectory estimate = Line(TrajectoryFormat::kTum, {0, 1, 2}, {0.04, 0.26, 0.5});
  EXPECT_EQ(AssociateWithTruth(estimate, truth, 0.05, "k"), (std::vector<int>{0, 3, 5}));
  ExpectInputError([&] { AssociateWithTruth(estimate, truth, 0.03, "Ground_truth"); },
                   {"Ground_truth", "timestamp 0.04 (pose 0)", "within 0.03 s", "0 .. 0.5"});
  const Trajectory late = Line(TrajectoryFormat::kTum, {0, 1}, {0.2, 0.58});
  ExpectInputError([&] { AssociateWithTruth(late, truth, 0.05, "gt"); }, {"gt", "pose 1"});
}

TEST(AbsoluteTrajectoryError, ConstantOffsetIsThreeUnalignedZeroAligned) {
  std::mt19937 rng(3);
  Trajectory truth, estimate;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Isometry3d p = RandomPose(rng);
    truth.poses.push_back(p);
    Eigen::Isometry3d q = p;
    q.translation() += Eigen::Vector3d(1, 2, 2);  // |(1, 2, 2)| = 3
    estimate.poses.push_back(q);
  }
  std::vector<int> association(20);
  for (int i = 0; i < 20; ++i) association[i] = i;
  const TrajectoryError raw = AbsoluteTrajectoryError(estimate, truth, association, false);
  EXPECT_NEAR(raw.mean, 3, 1e-9);
  EXPECT_NEAR(raw.rmse, 3, 1e-9);
  EXPECT_NEAR(raw.median, 3, 1e-9);
  EXPECT_NEAR(raw.max, 3, 1e-9);
  EXPECT_FALSE(raw.aligned);
  const TrajectoryError aligned = AbsoluteTrajectoryError(estimate, truth, association, true);
  EXPECT_TRUE(aligned.aligned);
  EXPECT_NEAR(aligned.mean, 0, 1e-9);
  EXPECT_NEAR(aligned.max, 0, 1e-9);
  EXPECT_TRUE(aligned.alignment.translation().isApprox(Eigen::Vector3d(-1, -2, -2), 1e-9));
}

TEST(AbsoluteTrajectoryError, RotatedCopyIsZeroAfterAlignment) {
  std::mt19937 rng(5);
  Trajectory truth, estimate;
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  motion.translation() = Eigen::Vector3d(10, -4, 2);
  for (int i = 0; i < 30; ++i) {
    truth.poses.push_back(RandomPose(rng));
    estimate.poses.push_back(motion * truth.poses.back());
  }
  std::vector<int> association(30);
  for (int i = 0; i < 30; ++i) association[i] = i;
  EXPECT_GT(AbsoluteTrajectoryError(estimate, truth, association, false).mean, 1);
  const TrajectoryError e = AbsoluteTrajectoryError(estimate, truth, association, true);
  EXPECT_LT(e.max, 1e-9);
  EXPECT_TRUE(e.alignment.matrix().isApprox(motion.inverse().matrix(), 1e-9));
}

TEST(AbsoluteTrajectoryError, StatisticsOfUnequalDistances) {
  // Distances 1, 2, 3, 4 (associated out of order): mean 2.5, rmse sqrt(30 / 4), median 2.5.
  const Trajectory truth = Line(TrajectoryFormat::kKitti, {0, 1, 2, 3});
  Trajectory estimate = truth;
  const double shift[] = {3, 1, 4, 2};
  for (int i = 0; i < 4; ++i) estimate.poses[i].translation().y() += shift[i];
  const TrajectoryError e = AbsoluteTrajectoryError(estimate, truth, {0, 1, 2, 3}, false);
  EXPECT_DOUBLE_EQ(e.mean, 2.5);
  EXPECT_DOUBLE_EQ(e.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(e.median, 2.5);
  EXPECT_DOUBLE_EQ(e.max, 4);
  const TrajectoryError odd = AbsoluteTrajectoryError(estimate, truth, {0, 1, 2, 0}, false);
  // Pose 3 (x = 3, y = 2) against truth 0 (origin): sqrt(13); sorted 1, 3, sqrt(13), 4.
  EXPECT_DOUBLE_EQ(odd.median, 0.5 * (3 + std::sqrt(13.0)));
}

// The hint of openable_snaps and Python at an estimate that cannot be a drifting estimate of
// the truth's route: its aligned mean error beyond a quarter of the route's extent.
TEST(ConventionHint, OnlyBeyondAQuarterOfTheRoutesExtent) {
  // The truth: 0, 1, ..., 40 m along x; extent 40 m, a quarter 10 m.
  std::vector<long> ids;
  for (long i = 0; i <= 40; ++i) ids.push_back(i);
  const Trajectory truth = Line(TrajectoryFormat::kKitti, ids);
  TrajectoryError aligned;
  aligned.aligned = true;
  aligned.mean = 10.0;  // a quarter: drift, no hint
  EXPECT_EQ(ConventionHint(aligned, truth), "");
  aligned.mean = 10.5;
  const std::string hint = ConventionHint(aligned, truth);
  EXPECT_EQ(hint,
            "the input is 10.5 m from the ground truth on average even after alignment, on a "
            "route 40.0 m across: more than drift. Check Snaps_world_to_camera (1 when the file "
            "holds world-to-camera matrices, as SO-DSO's poses_history_file.txt), "
            "Snaps_trajectory_format and Snaps_ground_truth_format, and that both cover the same "
            "frames.");
  const ConventionWords python = {"the estimate", "world_to_camera", "True", "the formats"};
  const std::string words = ConventionHint(aligned, truth, python);
  EXPECT_EQ(words.rfind("the estimate is 10.5 m", 0), 0u) << words;
  EXPECT_NE(words.find("Check world_to_camera (True when"), std::string::npos) << words;
  EXPECT_EQ(ConventionHint(aligned, Trajectory()), "");  // no truth: nothing to compare
}

// SO-DSO's keyframes of KITTI 00 are world-to-camera: read as they are, the trajectory is
// hundreds of metres off its route even after alignment, and the hint says why; read with
// world_to_camera, it drifts by about 10 m and nothing is hinted.
TEST(ConventionHint, SoDsoKeyframesReadWithoutWorldToCamera) {
  const std::string root = DatasetsDir() + "/kitti_trajectories";
  OPENABLE_REQUIRE_PATH(root);
  const std::string vo = root + "/vo_so_dso/seq00/poses_history_file.txt";
  const Trajectory truth = ReadTrajectory(root + "/poses/00.txt", TrajectoryFormat::kKitti);
  for (const bool inverted : {false, true}) {
    const Trajectory estimate = ReadTrajectory(vo, TrajectoryFormat::kKittiWithId, inverted);
    const std::vector<int> a = AssociateWithTruth(estimate, truth, 0.02, "truth");
    const TrajectoryError aligned = AbsoluteTrajectoryError(estimate, truth, a, true);
    // The route's extent computed here, independently of the hint.
    Eigen::AlignedBox3d box;
    for (const Eigen::Isometry3d& p : truth.poses) box.extend(p.translation());
    const double quarter = 0.25 * box.diagonal().norm();
    EXPECT_EQ(ConventionHint(aligned, truth).empty(), aligned.mean <= quarter) << inverted;
    EXPECT_EQ(ConventionHint(aligned, truth).empty(), inverted) << aligned.mean << " " << quarter;
  }
}

}  // namespace
}  // namespace openable::snaps
