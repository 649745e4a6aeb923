// The library's batch path (OpenABLE/online/online.h, OpenABLE/evaluation/) gives what
// Test_OpenABLE gives from a configuration, on real KITTI 00 frames 0-1699: the same normalised
// sequence matrix and the same evaluation figures. docs/library.md quotes this code.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "OpenABLE/OpenABLE.h"
#include "tests/e2e/e2e_support.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using e2e::Outcome;
using e2e::ReadJson;
using e2e::ReadNpy;
using e2e::RunFigure;

TEST(Library, BatchPathGivesTestOpenablesMatrixAndFigures) {
  const std::string data = testing::DatasetsDir() + "/kitti00_first1700";
  OPENABLE_REQUIRE_PATH(data);
  const std::string dir = testing::TempDir();
  const Outcome o = e2e::RunTestOpenable(dir, e2e::Kitti00LoopSettings(data, 5));
  ASSERT_EQ(o.status, 0) << o.err;
  const cv::Mat1f cli = ReadNpy(dir + "/m.npy");
  ASSERT_EQ(cli.rows, 1700);

  // --- as in docs/library.md ---
  std::vector<cv::Mat> images;
  for (int i = 0; i < 1700; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/image_0/%06d.png", i);
    images.push_back(cv::imread(data + name, cv::IMREAD_UNCHANGED));
  }
  OnlineOptions options;  // LDB 256 bits, global description
  const cv::Mat rows = DescribeImages(images, options);
  const cv::Mat1f matrix = DistanceMatrix(rows, /*sequence_length=*/5);

  GroundTruthOptions truth_options;
  truth_options.type = GroundTruthType::kKitti;
  truth_options.radius = 5.0;
  truth_options.heading_limit = 45.0;
  truth_options.min_frame_gap = 100;
  truth_options.axes = "xz";
  GroundTruth truth;
  truth.references = 1700;
  truth.matches = PairsFromPoses(
      ReadPoses(data + "/poses/00_first1700.txt", GroundTruthType::kKitti), {}, truth_options);
  EvaluationOptions evaluation;
  evaluation.tolerance = 3;
  evaluation.exclusion = 100;
  const EvaluationLayout layout = EvaluationLayout::LoopClosure(1700);
  const PerQueryResult figures = EvaluatePerQuery(matrix, layout, truth, evaluation);
  const AblePResult able_p = EvaluateAbleP(matrix, layout, truth, evaluation);
  // --- end of the quoted part ---

  double worst = 0;
  for (int i = 0; i < 1700; ++i)
    for (int j = 0; j < 1700; ++j)
      worst = std::max(worst, double(std::abs(matrix(i, j) - cli(i, j))));
  EXPECT_LT(worst, 1e-6);
  const Json written = ReadJson(dir + "/eval.json");
  const Json& run = written.at("runs").at(0);
  EXPECT_NEAR(figures.auc, RunFigure(run, "auc").get<double>(), 1e-6);
  EXPECT_NEAR(figures.recall_at_1, RunFigure(run, "recall_at_1").get<double>(), 1e-6);
  EXPECT_NEAR(figures.max_f1, RunFigure(run, "max_f1").get<double>(), 1e-6);
  EXPECT_NEAR(able_p.average_precision, RunFigure(run, "average_precision_percent").get<double>(),
              1e-4);
  EXPECT_GT(figures.auc, 0.5);  // the loop of frames 1559-1641 is found
  std::printf("library path: AUC %.3f, R@1 %.3f, ABLE-P AP %.2f %% (Test_OpenABLE: AUC %s)\n",
              figures.auc, figures.recall_at_1, able_p.average_precision,
              RunFigure(run, "auc").dump().c_str());
}

}  // namespace
}  // namespace openable
