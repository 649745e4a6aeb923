// SNAPS's search on real frames: KITTI 00, frames 0-1699 (../shared/datasets; skipped when
// absent), the ground-truth poses as the trajectory.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "OpenABLE/snaps/loops.h"
#include "tests/test_support.h"

namespace openable::snaps {
namespace {

Trajectory ReadKittiPoses(const std::string& path) {
  Trajectory t;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) s >> m(r, c);
    if (!s) continue;
    t.frame_ids.push_back(t.Size());
    t.poses.emplace_back(m);
  }
  return t;
}

TEST(KittiSearch, LoopsFoundAreRealRevisits) {
  const std::string dir = openable::testing::DatasetsDir() + "/kitti00_first1700";
  OPENABLE_REQUIRE_PATH(dir + "/image_0");
  const Trajectory truth = ReadKittiPoses(dir + "/poses/00_first1700.txt");
  ASSERT_EQ(truth.Size(), 1700);
  const ImageSearchResult r =
      SearchLoopsInImages(dir + "/image_0", "png", 0, truth, SearchOptions());
  ASSERT_EQ(r.steps.size(), 1700u);
  ASSERT_FALSE(r.loops.empty());
  int within = 0, in_revisit = 0;
  for (const LoopPair& l : r.loops) {
    const double d =
        (truth.poses[l.query].translation() - truth.poses[l.reference].translation()).norm();
    within += d < 5;
    in_revisit += l.query >= 1559 && l.query <= 1641 && l.reference >= 108 && l.reference <= 180;
    EXPECT_GE(l.similarity, 0.75);
    EXPECT_GE(l.query - l.reference, 100);
  }
  EXPECT_GE(within * 10, static_cast<int>(r.loops.size()) * 8) << "of " << r.loops.size();
  EXPECT_GE(in_revisit, 1);
  EXPECT_EQ(r.correction_seconds.size(), r.loops.size());
  // The corrected trajectory stays near the truth (loops pull towards true neighbours).
  for (int i = 0; i < 1700; ++i)
    ASSERT_LT((r.corrected.poses[i].translation() - truth.poses[i].translation()).norm(), 5.0) << i;
}

}  // namespace
}  // namespace openable::snaps
