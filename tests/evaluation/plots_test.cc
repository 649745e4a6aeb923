// The figures: sizes, and pixels at the places the layout of plots.cc puts them (the layout
// constants are repeated here from the comment at the top of OpenABLE/evaluation/plots.cc).
#include "OpenABLE/evaluation/plots.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

namespace openable {
namespace {

// RenderPrPlot layout.
constexpr int kTitleHeight = 40;
constexpr int kPanelWidth = 700;
constexpr int kPanelHeight = 600;
constexpr int kPlotLeft = 75;     // from the panel's left edge
constexpr int kPlotWidth = 600;   // recall 0 .. 1
constexpr int kPlotTop = 90;      // precision 1, from the top of the figure
constexpr int kPlotHeight = 490;  // precision 1 .. 0
// Okabe-Ito blue and orange (BGR), the first two series.
const cv::Vec3b kBlue(178, 114, 0);
const cv::Vec3b kOrange(0, 159, 230);

cv::Point PlotPixel(int panel, double recall, double precision) {
  return {static_cast<int>(std::lround(panel * kPanelWidth + kPlotLeft + recall * kPlotWidth)),
          static_cast<int>(std::lround(kPlotTop + kPlotHeight - precision * kPlotHeight))};
}

bool Near(const cv::Vec3b& a, const cv::Vec3b& b, int tolerance) {
  for (int ch = 0; ch < 3; ++ch)
    if (std::abs(static_cast<int>(a[ch]) - static_cast<int>(b[ch])) > tolerance) return false;
  return true;
}

// Whether a pixel within `radius` of `at` has (nearly) `colour`.
bool ColourAround(const cv::Mat3b& img, cv::Point at, const cv::Vec3b& colour, int radius = 2) {
  for (int y = at.y - radius; y <= at.y + radius; ++y)
    for (int x = at.x - radius; x <= at.x + radius; ++x)
      if (x >= 0 && y >= 0 && x < img.cols && y < img.rows && Near(img(y, x), colour, 30))
        return true;
  return false;
}

int CountColour(const cv::Mat3b& img, cv::Rect area, const cv::Vec3b& colour) {
  int n = 0;
  for (int y = area.y; y < area.y + area.height; ++y)
    for (int x = area.x; x < area.x + area.width; ++x) n += Near(img(y, x), colour, 30) ? 1 : 0;
  return n;
}

CurvePoint Point(double recall, double precision) {
  CurvePoint p;
  p.recall = recall;
  p.precision = precision;
  return p;
}

// Through (0.25, 1), (0.5, 0.5), (0.75, 0.4).
std::vector<CurvePoint> KnownCurve() {
  return {Point(0.25, 1.0), Point(0.5, 0.5), Point(0.75, 0.4)};
}

TEST(PrPlot, TwoPanelsAre1400x640) {
  const cv::Mat3b img = RenderPrPlot({{"a", KnownCurve(), KnownCurve()}}, "Title", 7);
  EXPECT_EQ(img.cols, 2 * kPanelWidth);
  EXPECT_EQ(img.rows, kTitleHeight + kPanelHeight);
}

TEST(PrPlot, OnePanelWhenEveryAblePIsEmpty) {
  const cv::Mat3b img =
      RenderPrPlot({{"a", KnownCurve(), {}}, {"b", KnownCurve(), {}}}, "Title", 7);
  EXPECT_EQ(img.cols, kPanelWidth);
  EXPECT_EQ(img.rows, kTitleHeight + kPanelHeight);
  // No series at all: one empty panel.
  const cv::Mat3b empty = RenderPrPlot({}, "", 7);
  EXPECT_EQ(empty.cols, kPanelWidth);
  EXPECT_EQ(empty.rows, kTitleHeight + kPanelHeight);
}

TEST(PrPlot, BackgroundIsWhiteAndFrameBlack) {
  const cv::Mat3b img = RenderPrPlot({{"a", KnownCurve(), KnownCurve()}}, "Title", 7);
  EXPECT_EQ(img(0, 0), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(img(img.rows - 1, img.cols - 1), cv::Vec3b(255, 255, 255));
  // Inside the plot area, off the grid and the curve.
  EXPECT_EQ(img(PlotPixel(0, 0.85, 0.85)), cv::Vec3b(255, 255, 255));
  // The frame's left edge at precision 0.55 and its bottom edge at recall 0.95.
  EXPECT_EQ(img(PlotPixel(0, 0.0, 0.55)), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(img(PlotPixel(0, 0.95, 0.0)), cv::Vec3b(0, 0, 0));
  // A grid line at recall 0.3 is light grey.
  const cv::Vec3b grid = img(PlotPixel(0, 0.3, 0.85));
  EXPECT_GT(grid[0], 180);
  EXPECT_LT(grid[0], 250);
}

TEST(PrPlot, KnownPointOfThePerQueryCurveHasTheSeriesColour) {
  const cv::Mat3b img = RenderPrPlot({{"a", KnownCurve(), {}}}, "", 7);
  EXPECT_TRUE(ColourAround(img, PlotPixel(0, 0.5, 0.5), kBlue));
  // The step path: (0, 1) -> (0.25, 1) -> (0.25, 0.5) -> (0.5, 0.5) -> (0.5, 0.4) ...
  EXPECT_TRUE(ColourAround(img, PlotPixel(0, 0.1, 1.0), kBlue));
  EXPECT_TRUE(ColourAround(img, PlotPixel(0, 0.25, 0.75), kBlue));
  EXPECT_TRUE(ColourAround(img, PlotPixel(0, 0.625, 0.4), kBlue));
  // Off the path.
  EXPECT_FALSE(ColourAround(img, PlotPixel(0, 0.5, 0.8), kBlue));
  EXPECT_FALSE(ColourAround(img, PlotPixel(0, 0.375, 0.75), kBlue));
  EXPECT_FALSE(ColourAround(img, PlotPixel(0, 0.9, 0.4), kBlue));  // the curve ends at 0.75
}

TEST(PrPlot, SecondSeriesInTheAblePPanelHasTheSecondColour) {
  const std::vector<CurvePoint> able = {Point(0, 1), Point(0.3, 0.9), Point(0.6, 0.7)};
  const cv::Mat3b img = RenderPrPlot({{"a", KnownCurve(), {}}, {"b", KnownCurve(), able}}, "", 3);
  ASSERT_EQ(img.cols, 2 * kPanelWidth);
  // Step path: (0, 1) -> (0, 0.9) -> (0.3, 0.9) -> (0.3, 0.7) -> (0.6, 0.7).
  EXPECT_TRUE(ColourAround(img, PlotPixel(1, 0.45, 0.7), kOrange));
  EXPECT_TRUE(ColourAround(img, PlotPixel(1, 0.3, 0.8), kOrange));
  EXPECT_TRUE(ColourAround(img, PlotPixel(1, 0.15, 0.9), kOrange));
  EXPECT_FALSE(ColourAround(img, PlotPixel(1, 0.45, 0.9), kOrange));
  EXPECT_FALSE(ColourAround(img, PlotPixel(1, 0.45, 0.7), kBlue));
  // Series a has no ABLE-P points: nothing blue in the upper half of that plot area.
  EXPECT_EQ(
      CountColour(img, {kPanelWidth + kPlotLeft + 2, kPlotTop + 2, kPlotWidth - 4, kPlotHeight / 2},
                  kBlue),
      0);
}

TEST(PrPlot, EmptyCurveDrawsNothing) {
  const cv::Mat3b img = RenderPrPlot({{"empty", {}, {}}, {"b", KnownCurve(), {}}}, "", 7);
  // Nothing blue above the legend (lower left) in the plot area.
  EXPECT_EQ(
      CountColour(img, {kPlotLeft + 2, kPlotTop + 2, kPlotWidth - 4, kPlotHeight - 120}, kBlue), 0);
  // But the legend still has its (blue) line sample.
  EXPECT_GT(CountColour(img, {kPlotLeft, kPlotTop + kPlotHeight - 120, 80, 120}, kBlue), 10);
  // And the second series is drawn in orange.
  EXPECT_TRUE(ColourAround(img, PlotPixel(0, 0.5, 0.5), kOrange));
}

TEST(PrPlot, ManySeriesAndLongLabelsStayInsideTheFigure) {
  std::vector<PrSeries> series;
  for (int i = 0; i < 30; ++i)
    series.push_back({std::string(200, 'x'), KnownCurve(), KnownCurve()});
  const cv::Mat3b img = RenderPrPlot(series, std::string(300, 'T'), 7);
  EXPECT_EQ(img.cols, 2 * kPanelWidth);
  EXPECT_EQ(img.rows, kTitleHeight + kPanelHeight);
  // The legend box does not run into the right-hand panel's margin.
  EXPECT_EQ(img(PlotPixel(0, 1.0, 0.5).y, kPanelWidth + 5), cv::Vec3b(255, 255, 255));
}

// ---------------------------------------------------------------------------------------------
// Overlay.

GroundTruth Truth(std::vector<std::vector<int>> matches, int references) {
  GroundTruth t;
  t.matches = std::move(matches);
  t.references = references;
  return t;
}

// Centre pixel of block cell (q, r) with enlargement k.
// The pixel at the middle of the enlarged cell (q, r): the block starts after the axes.
cv::Vec3b Cell(const cv::Mat3b& img, int k, int q, int r) {
  return img(kOverlayAxisTop + q * k + k / 2, kOverlayAxisLeft + r * k + k / 2);
}

// The pixel (y, x) of the block.
cv::Vec3b At(const cv::Mat3b& img, int y, int x) {
  return img(kOverlayAxisTop + y, kOverlayAxisLeft + x);
}

const cv::Vec3b kGreen(0, 200, 0);
const cv::Vec3b kRed(0, 0, 230);

// 4 x 5 block: k = ceil(600 / 5) = 120.
cv::Mat1f SmallBlock() {
  return (cv::Mat1f(4, 5) << 0.9f, 0.1f, 0.5f, 0.7f, 0.8f,  //
          0.3f, 0.6f, 0.2f, 0.9f, 0.4f,                     //
          0.5f, 0.5f, 0.6f, 0.35f, 0.9f,                    //
          0.8f, 0.7f, 0.6f, 0.5f, -0.2f);
}

PerQueryResult SmallResult() {
  PerQueryResult r;
  r.best = {1, 2, 3, 4};
  r.best_distance = {0.1f, 0.2f, 0.35f, 0.45f};
  r.score = r.best_distance;  // the distance score
  r.positive = {1, 1, 0, 1};
  r.correct = {1, 0, 0, 1};
  return r;
}

TEST(Overlay, SizeIsTheEnlargedBlockAndALegendStrip) {
  const cv::Mat3b img = RenderOverlay(SmallBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), SmallResult(), 0.3);
  EXPECT_EQ(img.cols, kOverlayAxisLeft + 600);
  EXPECT_GE(img.rows, kOverlayAxisTop + 480 + 25);
  EXPECT_LE(img.rows, kOverlayAxisTop + 480 + 90);
  // The strip below the block is white with some dark text.
  const int below = kOverlayAxisTop + 480;
  const cv::Mat3b strip = img(cv::Rect(0, below, img.cols, img.rows - below));
  EXPECT_EQ(strip(0, 0), cv::Vec3b(255, 255, 255));
  EXPECT_GT(CountColour(strip, {0, 0, strip.cols, strip.rows}, cv::Vec3b(0, 0, 0)), 50);
  EXPECT_GT(CountColour(strip, {0, 0, strip.cols, strip.rows}, kGreen), 50);
  EXPECT_GT(CountColour(strip, {0, 0, strip.cols, strip.rows}, kRed), 50);
}

TEST(Overlay, AcceptedMatchesAreGreenWhenCorrectAndRedWhenWrong) {
  const cv::Mat3b img = RenderOverlay(SmallBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), SmallResult(), 0.3);
  const int k = 120;
  EXPECT_EQ(Cell(img, k, 0, 1), kGreen);  // q0 best c1 at 0.1, correct
  EXPECT_EQ(Cell(img, k, 1, 2), kRed);    // q1 best c2 at 0.2, wrong
  // The whole enlarged cell is marked.
  EXPECT_EQ(At(img, 0, k), kGreen);
  EXPECT_EQ(At(img, k - 1, 2 * k - 1), kGreen);
  // Above the threshold: not marked (q2 at 0.35, q3 at 0.45): plain grey.
  EXPECT_EQ(Cell(img, k, 2, 3), cv::Vec3b(89, 89, 89));  // round(255 * 0.35) = 89
}

// The block's frame numbers: a tick at the middle of every column and row of a 4 x 5 block
// (fewer than 8 frames: every frame), with dark label text above and to the left.
TEST(Overlay, FrameNumbersAlongTheTopAndTheLeft) {
  const cv::Mat3b img = RenderOverlay(SmallBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), SmallResult(), 0.3);
  const int k = 120;
  const cv::Vec3b tick(90, 90, 90);
  for (int c = 0; c < 5; ++c)
    EXPECT_EQ(img(kOverlayAxisTop - 3, kOverlayAxisLeft + c * k + k / 2), tick) << c;
  for (int q = 0; q < 4; ++q)
    EXPECT_EQ(img(kOverlayAxisTop + q * k + k / 2, kOverlayAxisLeft - 3), tick) << q;
  EXPECT_EQ(img(kOverlayAxisTop - 3, kOverlayAxisLeft + k / 4), cv::Vec3b(255, 255, 255));
  EXPECT_GT(CountColour(img, {kOverlayAxisLeft, 0, 5 * k, kOverlayAxisTop}, cv::Vec3b(0, 0, 0)),
            20);
  EXPECT_GT(CountColour(img, {0, kOverlayAxisTop, kOverlayAxisLeft, 4 * k}, cv::Vec3b(0, 0, 0)),
            20);
}

TEST(Overlay, GreyLevelIsTheRoundedValue) {
  const cv::Mat3b img = RenderOverlay(SmallBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), SmallResult(), 0.3);
  const int k = 120;
  EXPECT_EQ(Cell(img, k, 0, 0), cv::Vec3b(230, 230, 230));  // 255 * 0.9 = 229.5 -> 230
  EXPECT_EQ(Cell(img, k, 2, 0), cv::Vec3b(128, 128, 128));  // 127.5 -> 128
  EXPECT_EQ(Cell(img, k, 1, 0), cv::Vec3b(77, 77, 77));     // 76.5 -> 77
  EXPECT_EQ(At(img, k - 1, 0), cv::Vec3b(230, 230, 230));   // last pixel row of cell (0, 0)
  // Values are clamped to [0, 1]: the -0.2 of cell (3, 4) is black (it is not marked: 0.45).
  EXPECT_EQ(Cell(img, k, 3, 4), cv::Vec3b(0, 0, 0));
}

TEST(Overlay, GroundTruthIsTintedBlue) {
  const cv::Mat3b img = RenderOverlay(SmallBlock(), EvaluationLayout::QueryReference(4, 5),
                                      Truth({{1}, {4}, {}, {3}}, 5), SmallResult(), 0.3);
  const int k = 120;
  // (1, 4): truth, value 0.4 (grey 102), q1's best is elsewhere.
  const cv::Vec3b t = Cell(img, k, 1, 4);
  EXPECT_GT(t[0], t[2] + 60) << t;
  EXPECT_GT(t[0], 102) << t;
  // (3, 3): truth, value 0.5, q3's best (3, 4) is not accepted.
  const cv::Vec3b u = Cell(img, k, 3, 3);
  EXPECT_GT(u[0], u[2] + 60) << u;
  // A cell without truth stays grey.
  const cv::Vec3b g = Cell(img, k, 3, 2);
  EXPECT_EQ(g[0], g[2]);
}

TEST(Overlay, UsesTheBlockOfTheLayout) {
  // Two traversals of 3 frames each: the block is rows 3..5, columns 0..2.
  cv::Mat1f m(6, 6, 1.0f);
  m(3, 0) = 0.2f;
  m(5, 2) = 0.6f;
  PerQueryResult r;
  const cv::Mat3b img =
      RenderOverlay(m, EvaluationLayout::TwoTraversals(3, 3), Truth({{}, {}, {}}, 3), r, 0.5);
  const int k = 200;
  EXPECT_EQ(img.cols, kOverlayAxisLeft + 600);
  EXPECT_EQ(Cell(img, k, 0, 0), cv::Vec3b(51, 51, 51));
  EXPECT_EQ(Cell(img, k, 2, 2), cv::Vec3b(153, 153, 153));
  EXPECT_EQ(Cell(img, k, 1, 1), cv::Vec3b(255, 255, 255));
  EXPECT_THROW(RenderOverlay(cv::Mat1f(5, 6, 0.0f), EvaluationLayout::TwoTraversals(3, 3),
                             Truth({{}, {}, {}}, 3), r, 0.5),
               std::logic_error);
}

TEST(Overlay, OneByOneBlock) {
  PerQueryResult r;
  r.best = {0};
  r.best_distance = {0.25f};
  r.score = r.best_distance;
  r.correct = {1};
  const cv::Mat3b img = RenderOverlay(
      cv::Mat1f(1, 1, 0.25f), EvaluationLayout::QueryReference(1, 1), Truth({{0}}, 1), r, 0.5);
  EXPECT_EQ(img.cols, kOverlayAxisLeft + 600);
  EXPECT_GT(img.rows, kOverlayAxisTop + 600);
  EXPECT_EQ(At(img, 0, 0), kGreen);
  EXPECT_EQ(At(img, 599, 599), kGreen);
  EXPECT_EQ(At(img, 600, 599), cv::Vec3b(255, 255, 255));  // legend strip
}

TEST(Overlay, LargeBlockMarksAreAtLeast3x3) {
  // 3576 x 1788 block: k = 1.
  const int rows = 3576, cols = 1788;
  cv::Mat1f m(rows, cols);
  cv::randu(m, 0.0f, 1.0f);
  PerQueryResult r;
  r.best.assign(rows, -1);
  r.best_distance.assign(rows, 1.0f);
  r.correct.assign(rows, 0);
  r.best[1000] = 500;
  r.best_distance[1000] = 0.1f;
  r.correct[1000] = 1;
  r.best[2000] = 1200;
  r.best_distance[2000] = 0.1f;
  r.correct[2000] = 0;
  r.score = r.best_distance;
  GroundTruth t = Truth(std::vector<std::vector<int>>(rows), cols);
  for (int q = 0; q < rows; ++q) t.matches[q] = {q / 2};
  const cv::Mat3b img = RenderOverlay(m, EvaluationLayout::QueryReference(rows, cols), t, r, 0.5);
  EXPECT_EQ(img.cols, kOverlayAxisLeft + cols);
  EXPECT_GT(img.rows, kOverlayAxisTop + rows);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      EXPECT_EQ(At(img, 1000 + dy, 500 + dx), kGreen);
      EXPECT_EQ(At(img, 2000 + dy, 1200 + dx), kRed);
    }
  // Untouched: a random cell away from the marks and the truth diagonal.
  EXPECT_EQ(At(img, 10, 1000)[0], static_cast<int>(std::lround(255 * m(10, 1000))));
  EXPECT_EQ(At(img, 10, 1000)[0], At(img, 10, 1000)[2]);
  // Frame numbers every 500 rows (3576 / 8 rounded up to 1, 2 or 5 x 10^n) and every 500
  // columns (1788 / 8 -> 500): a tick beside row 500 and above column 1500, none between.
  const cv::Vec3b tick(90, 90, 90), white(255, 255, 255);
  EXPECT_EQ(img(kOverlayAxisTop + 500, kOverlayAxisLeft - 3), tick);
  EXPECT_EQ(img(kOverlayAxisTop + 250, kOverlayAxisLeft - 3), white);
  EXPECT_EQ(img(kOverlayAxisTop - 3, kOverlayAxisLeft + 1500), tick);
  EXPECT_EQ(img(kOverlayAxisTop - 3, kOverlayAxisLeft + 1250), white);
}

}  // namespace
}  // namespace openable
