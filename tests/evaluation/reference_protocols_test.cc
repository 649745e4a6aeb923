// The protocols of VPR-Bench and VPR_Tutorial against the figures their own code computes on
// the same matrices (tests/data/reference_protocols/make.py ran performance_comparison.py and
// evaluation/metrics.py with Debian's numpy and scikit-learn; expected.json holds the results).
#include "OpenABLE/evaluation/reference_protocols.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/matrix_file.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using nlohmann::json;

std::string DataDir() { return testing::SourceDir() + "/tests/data/reference_protocols/"; }

const json& Expected() {
  static const json expected = [] {
    std::ifstream in(DataDir() + "expected.json");
    std::stringstream text;
    text << in.rdbuf();
    return json::parse(text.str());
  }();
  return expected;
}

// A figure of expected.json: a number, or null for one the reference code cannot compute.
void ExpectFigure(double actual, const json& expected, const std::string& what) {
  if (expected.is_null()) {
    EXPECT_TRUE(std::isnan(actual)) << what << ": " << actual;
  } else {
    EXPECT_NEAR(actual, expected.get<double>(), 1e-12) << what;
  }
}

void ExpectFigures(const std::vector<double>& actual, const json& expected,
                   const std::string& what) {
  ASSERT_EQ(actual.size(), expected.size()) << what;
  for (std::size_t i = 0; i < actual.size(); ++i)
    ExpectFigure(actual[i], expected[i], what + "[" + std::to_string(i) + "]");
}

GroundTruth Load(GroundTruthType type, const std::string& file, const EvaluationLayout& layout,
                 const std::string& soft = "") {
  GroundTruthOptions o;
  o.type = type;
  o.path = DataDir() + file;
  if (!soft.empty()) o.soft_path = DataDir() + soft;
  return LoadGroundTruth(o, layout, layout.queries, layout.references);
}

void ExpectVprBench(const VprBenchResult& r, const json& e) {
  ExpectFigure(r.auc_pr, e["auc_pr"], "auc_pr");
  ExpectFigure(r.extended_precision, e["extended_precision"], "extended_precision");
  ExpectFigure(r.recall_at_100p, e["recall_at_100p"], "recall_at_100p");
  EXPECT_EQ(r.right_best_matches, e["right_best_matches"].get<int>());
  if (e.contains("recall_at_n")) ExpectFigures(r.recall_at_n, e["recall_at_n"], "recall_at_n");
  ExpectFigures(r.precision, e["precision"], "precision");
  ExpectFigures(r.recall, e["recall"], "recall");
}

void ExpectVprTutorial(const VprTutorialResult& r, const json& e) {
  ExpectFigure(r.auc_multi, e["auc_multi"], "auc_multi");
  ExpectFigure(r.recall_at_100p_multi, e["recall_at_100p_multi"], "recall_at_100p_multi");
  ExpectFigures(r.precision_multi, e["precision_multi"], "precision_multi");
  ExpectFigures(r.recall_multi, e["recall_multi"], "recall_multi");
  EXPECT_EQ(r.single, e.contains("auc_single"));
  if (e.contains("auc_single")) {
    ExpectFigure(r.auc_single, e["auc_single"], "auc_single");
    ExpectFigure(r.recall_at_100p_single, e["recall_at_100p_single"], "recall_at_100p_single");
    ExpectFigures(r.precision_single, e["precision_single"], "precision_single");
    ExpectFigures(r.recall_single, e["recall_single"], "recall_single");
  }
  if (e.contains("recall_at_k")) ExpectFigures(r.recall_at_k, e["recall_at_k"], "recall_at_k");
}

// 7 queries x 9 references, query 4 without a true reference, VPR-Bench's object array as
// numpy's np.save pickles it in Python 3.
TEST(VprBenchProtocol, HandMadeMatrixGivesTheFiguresOfVprBench) {
  const cv::Mat1f d = ReadMatrixFile(DataDir() + "hand_distances.npy");
  const auto layout = EvaluationLayout::QueryReference(d.rows, d.cols);
  const GroundTruth gt = Load(GroundTruthType::kVprBench, "hand_ground_truth.npy", layout);
  const VprBenchResult r = EvaluateVprBench(d, layout, gt, 0);
  EXPECT_EQ(r.queries, 7);
  EXPECT_EQ(r.queries_with_truth, 6);
  ExpectVprBench(r, Expected()["hand"]["vpr_bench"]);
}

TEST(VprTutorialProtocol, HandMadeMatrixGivesTheFiguresOfVprTutorial) {
  const cv::Mat1f d = ReadMatrixFile(DataDir() + "hand_distances.npy");
  const auto layout = EvaluationLayout::QueryReference(d.rows, d.cols);
  const GroundTruth gt = Load(GroundTruthType::kVprTutorial, "hand_gt_hard.npy", layout);
  EXPECT_TRUE(gt.soft.empty());
  ExpectVprTutorial(EvaluateVprTutorial(d, layout, gt, 0), Expected()["hand"]["vpr_tutorial"]);
}

// GTsoft from its own file and from GT.npz: the cells it adds are ignored, and single-match
// is not computed (createPR refuses GTsoft with single matching).
TEST(VprTutorialProtocol, SoftGroundTruthFromNpyOrNpzGivesTheFiguresOfVprTutorial) {
  const cv::Mat1f d = ReadMatrixFile(DataDir() + "hand_distances.npy");
  const auto layout = EvaluationLayout::QueryReference(d.rows, d.cols);
  for (const auto& [hard, soft] :
       {std::pair<std::string, std::string>{"hand_gt_hard.npy", "hand_gt_soft.npy"},
        {"hand_gt.npz", ""}}) {
    SCOPED_TRACE(hard);
    const GroundTruth gt = Load(GroundTruthType::kVprTutorial, hard, layout, soft);
    // make.py's two soft cells beyond GThard: (reference 4, query 1) and (reference 0, query 3).
    ASSERT_EQ(gt.soft.size(), 7u);
    EXPECT_EQ(gt.soft[1], std::vector<int>{4});
    EXPECT_EQ(gt.soft[3], std::vector<int>{0});
    EXPECT_EQ(gt.matches[2], (std::vector<int>{3, 4, 5}));
    const VprTutorialResult r = EvaluateVprTutorial(d, layout, gt, 0);
    EXPECT_TRUE(r.soft);
    ExpectVprTutorial(r, Expected()["hand"]["vpr_tutorial_soft"]);
  }
}

// Distances in steps of 1/8: equal best-match scores are one point of scikit-learn's curve,
// equal cells one step of createPR's thresholds.
TEST(ReferenceProtocols, EqualDistancesGiveTheReferenceFigures) {
  const cv::Mat1f d = ReadMatrixFile(DataDir() + "ties_distances.npy");
  const auto layout = EvaluationLayout::QueryReference(d.rows, d.cols);
  const GroundTruth gt = Load(GroundTruthType::kVprTutorial, "ties_gt_hard.npy", layout);
  ExpectVprBench(EvaluateVprBench(d, layout, gt, 0), Expected()["ties"]["vpr_bench"]);
  ExpectVprTutorial(EvaluateVprTutorial(d, layout, gt, 0), Expected()["ties"]["vpr_tutorial"]);
}

// OpenABLE's HOG matrix of Gardens Point (day_left queries, day_right references) with
// VPR-Bench's own ground-truth file (a Python 2 pickle whose last lists name references 200
// and 201, past the last, which are dropped), with and without Tolerance 2.
TEST(ReferenceProtocols, RealMatrixWithVprBenchsFileGivesTheReferenceFigures) {
  const cv::Mat1f d = ReadMatrixFile(DataDir() + "gardens_point_hog.npy");
  ASSERT_EQ(d.rows, 200);
  const auto layout = EvaluationLayout::QueryReference(d.rows, d.cols);
  const GroundTruth gt =
      Load(GroundTruthType::kVprBench, "vpr_bench_gardens_point_ground_truth_new.npy", layout);
  EXPECT_EQ(gt.matches[0], (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(gt.matches[199], (std::vector<int>{197, 198, 199}));
  EXPECT_EQ(gt.dropped, 3);  // 200 of query 198, 200 and 201 of query 199
  ExpectVprBench(EvaluateVprBench(d, layout, gt, 0), Expected()["real"]["vpr_bench"]);
  ExpectVprTutorial(EvaluateVprTutorial(d, layout, gt, 0), Expected()["real"]["vpr_tutorial"]);
  ExpectVprBench(EvaluateVprBench(d, layout, gt, 2), Expected()["real_tolerance_2"]["vpr_bench"]);
  ExpectVprTutorial(EvaluateVprTutorial(d, layout, gt, 2),
                    Expected()["real_tolerance_2"]["vpr_tutorial"]);
}

// R@N with equal distances at the N-th place, by hand: the lower reference index comes first.
TEST(ReferenceProtocols, EqualDistancesAtTheNthPlaceTakeTheLowerReferenceFirst) {
  // One query, 4 references; references 1 and 2 tie for the second place, 2 is true.
  cv::Mat1f d(1, 4);
  d << 0.1f, 0.5f, 0.5f, 0.9f;
  const auto layout = EvaluationLayout::QueryReference(1, 4);
  GroundTruth gt;
  gt.references = 4;
  gt.matches = {{2}};
  const VprBenchResult b = EvaluateVprBench(d, layout, gt, 0);
  ASSERT_EQ(b.recall_at_n.size(), 4u);  // N = 1 .. the 4 references
  EXPECT_EQ(b.recall_at_n, (std::vector<double>{0, 0, 1, 1}));
  const VprTutorialResult t = EvaluateVprTutorial(d, layout, gt, 0);
  EXPECT_EQ(t.recall_at_k[0], 0.0);
  EXPECT_TRUE(std::isnan(t.recall_at_k[1]));  // K = 5 > 4 references
}

TEST(ReferenceProtocols, OneSequenceIsRefusedNamingTheKey) {
  cv::Mat1f d(5, 5, 0.5f);
  const auto layout = EvaluationLayout::LoopClosure(5);
  GroundTruth gt;
  gt.references = 5;
  gt.matches.assign(5, {});
  try {
    EvaluateVprBench(d, layout, gt, 0);
    FAIL() << "a loop-closure layout was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("Evaluation_protocol: vpr_bench needs two traversals", 0),
              0u)
        << e.what();
  }
  EXPECT_THROW(EvaluateVprTutorial(d, layout, gt, 0), InputError);
}

// The table of protocols gives each protocol's figures as its reference code computes them:
// the row every report shows, the JSON member and the curve file.
TEST(ReferenceProtocols, TheTableGivesTheReferenceCodesFiguresToEveryReport) {
  const cv::Mat1f d = ReadMatrixFile(DataDir() + "hand_distances.npy");
  const auto layout = EvaluationLayout::QueryReference(d.rows, d.cols);
  const GroundTruth gt = Load(GroundTruthType::kVprBench, "hand_ground_truth.npy", layout);
  const std::vector<ProtocolFigures> f =
      EvaluateReferenceProtocols(d, layout, gt, ParseEvaluationProtocols("all"), 0);
  ASSERT_EQ(f.size(), ReferenceProtocols().size());
  ASSERT_EQ(f[0].protocol, "vpr_bench");
  const json& e = Expected()["hand"]["vpr_bench"];
  ExpectFigure(f[0].auc, e["auc_pr"], "auc_pr");
  ExpectFigure(f[0].recall_at_100p, e["recall_at_100p"], "recall_at_100p");
  // The JSON keeps 9 significant digits.
  EXPECT_NEAR(f[0].json["auc_pr"].get<double>(), e["auc_pr"].get<double>(), 1e-8);
  EXPECT_EQ(f[0].json["right_best_matches"].get<int>(), e["right_best_matches"].get<int>());
  // The curve file: a header, then one line per point of the reference code's curve.
  std::istringstream csv(f[0].csv);
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "precision,recall");
  std::size_t points = 0;
  while (std::getline(csv, line)) {
    ASSERT_LT(points, e["precision"].size());
    EXPECT_NEAR(std::stod(line.substr(0, line.find(','))), e["precision"][points].get<double>(),
                1e-8);
    ++points;
  }
  EXPECT_EQ(points, e["precision"].size());
  ASSERT_EQ(f[1].protocol, "vpr_tutorial");
  EXPECT_EQ(f[1].csv.rfind("matching,precision,recall\n", 0), 0u);
  for (const ReferenceProtocol& p : ReferenceProtocols())
    EXPECT_EQ(std::string(p.csv_suffix), "_" + std::string(p.name) + ".csv");
}

TEST(EvaluationProtocolKey, ParsesNamesListsAndAll) {
  using P = EvaluationProtocols;
  EXPECT_EQ(ParseEvaluationProtocols("openable"), (P{true, {}}));
  EXPECT_EQ(ParseEvaluationProtocols("VPR_Bench"), (P{false, {"vpr_bench"}}));
  EXPECT_EQ(ParseEvaluationProtocols("openable, vpr_tutorial"), (P{true, {"vpr_tutorial"}}));
  // The table's order, whatever the order given; a name given twice is one.
  EXPECT_EQ(ParseEvaluationProtocols("vpr_tutorial,vpr_bench,vpr_tutorial"),
            (P{false, {"vpr_bench", "vpr_tutorial"}}));
  EXPECT_EQ(ParseEvaluationProtocols("all"), (P{true, {"vpr_bench", "vpr_tutorial"}}));
  EXPECT_EQ(EvaluationProtocolsText({true, {"vpr_bench", "vpr_tutorial"}}),
            "openable,vpr_bench,vpr_tutorial");
  for (const char* bad : {"", "vpr", "openable,,vpr_bench", "seqslam"}) {
    try {
      ParseEvaluationProtocols(bad);
      FAIL() << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("Evaluation_protocol: ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find("expected openable, vpr_bench, vpr_tutorial"),
                std::string::npos);
    }
  }
}

}  // namespace
}  // namespace openable
