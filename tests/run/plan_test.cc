// The run plan (OpenABLE/run/plan.h): the check phase reads no frame, refuses a bad source
// before any work, decides the mode from the frame counts, and the compute phase runs the plan
// as it is.
#include "OpenABLE/run/plan.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/progress.h"
#include "OpenABLE/run/pipeline.h"
#include "config/config.h"
#include "tests/test_support.h"

namespace openable {
namespace {

namespace fs = std::filesystem;

// A folder of `n` files named like PNG frames that hold no image.
std::string FolderOfNonImages(const std::string& name, int n) {
  const std::string dir = testing::TempDir() + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (int i = 0; i < n; ++i) {
    char file[32];
    std::snprintf(file, sizeof file, "/f%03d.png", i);
    testing::WriteBytes(dir + file, "not an image");
  }
  return dir;
}

Config FolderRun(const std::string& dir) {
  Config c;
  c.input.images_path = dir;
  c.input.images_format = "png";
  c.descriptor.name = "LDB";
  c.matching.sequence_length = 2;
  return c;
}

TEST(RunPlan, ChecksWithoutReadingAFrameAndTheComputePhaseReadsThem) {
  // Every file is unreadable as an image: the plan is made all the same (its checks open the
  // folder and count the frames), and only the compute phase meets the first bad frame.
  const std::string dir = FolderOfNonImages("plan_non_images", 12);
  const RunPlan plan = PlanRun(FolderRun(dir));
  ASSERT_EQ(plan.sources.size(), 1u);
  EXPECT_EQ(plan.sources[0]->Size(), 12);
  EXPECT_EQ(plan.names, std::vector<std::string>{"LDB"});
  EXPECT_FALSE(plan.head.bounded);
  ProgressReporter silent(std::cerr, false, false);
  testing::ExpectInputError([&] { ComputeRun(plan, silent); }, {"f000.png"});
}

TEST(RunPlan, RefusesABadSecondFolderBeforeAnyWork) {
  Config c = FolderRun(FolderOfNonImages("plan_first", 12));
  c.input.images_path_2 = testing::TempDir() + "/plan_no_such_folder";
  testing::ExpectInputError([&] { PlanRun(c); }, {"Images_path_2", "plan_no_such_folder"});
}

TEST(RunPlan, DecidesTheModeFromTheFrameCounts) {
  Config c = FolderRun(FolderOfNonImages("plan_mode", 12));
  // 12 x 12 cells of 4 bytes, one direction: 576 bytes. A limit of 500 bytes makes the run
  // bounded (Matrix_mode 0), one of 600 bytes leaves it dense.
  const double gib = 1024.0 * 1024.0 * 1024.0;
  c.scale.matches_name = testing::TempDir() + "/plan_matches.csv";
  c.scale.memory_limit = 500 / gib;
  EXPECT_TRUE(PlanRun(c).head.bounded);
  EXPECT_NE(PlanRun(c).head.mode_reason.find("bounded (Matrix_mode 0: the 12x12 matrix"),
            std::string::npos);
  c.scale.memory_limit = 600 / gib;
  EXPECT_FALSE(PlanRun(c).head.bounded);
  // Both directions keep two matrices: 1152 bytes.
  c.matching.direction = SequenceDirection::kBoth;
  EXPECT_TRUE(PlanRun(c).head.bounded);
  // The auto mode's plans refuse a run that would be bounded.
  testing::ExpectInputError([&] { PlanRun(c, PlanScope::kSingleFrames); },
                            {"Auto: 1 compares dense matrices"});
  c.scale.matrix_mode = MatrixMode::kDense;
  EXPECT_FALSE(PlanRun(c).head.bounded);
}

TEST(RunPlan, FusedDescriptorsAreCreatedOnceEachWithTheirRowWidths) {
  Config c = FolderRun(FolderOfNonImages("plan_fused", 12));
  c.descriptor.name = "HOG+LDB";
  c.matching.fusion_weights = "1,1";
  const RunPlan plan = PlanRun(c);
  ASSERT_EQ(plan.descriptors.size(), 2u);
  ASSERT_EQ(plan.describers.size(), 2u);
  EXPECT_TRUE(plan.Fused());
  EXPECT_EQ(plan.head.descriptor, "HOG+LDB");
  for (size_t k = 0; k < 2; ++k)
    EXPECT_EQ(plan.head.descriptors[k].row_width, plan.describers[k]->RowWidth());
  EXPECT_EQ(plan.head.fusion_weights, (std::vector<double>{1.0, 1.0}));
}

}  // namespace
}  // namespace openable
