// Figures of an evaluation, drawn with OpenCV only (lines, rectangles, Hershey text).
//
// RenderPrPlot layout (pixels; tests/evaluation/plots_test.cc relies on these numbers):
//   figure: kTitleHeight (40) rows for the title, then one or two panels of kPanelWidth x
//     kPanelHeight (700 x 600) side by side: 1400 x 640 with two panels, 700 x 640 with one.
//   panel p (0 = per query, 1 = ABLE-P) starts at x = 700 p, y = 40. Its plot area spans
//     x from 700 p + 75 to 700 p + 675 (600 px) and y from 40 + 50 = 90 (precision 1) down to
//     640 - 60 = 580 (precision 0), so a curve point (recall r, precision p) is drawn at
//     x = 700 p + 75 + 600 r, y = 580 - 490 p (sub-pixel precision, anti-aliased, 2 px wide).
//   series i uses colour i mod 8 of the Okabe-Ito palette (kPalette).
//
// RenderOverlay layout: the block, enlarged by k = max(1, ceil(600 / max(rows, cols))), sits at
// the top left: block cell (q, r) covers output pixels x in [k r, k r + k), y in [k q, k q + k).
// The figure is max(k cols, 600) wide; a white legend strip (one or more 30 px lines) is below.
#include "OpenABLE/evaluation/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/drawing.h"

namespace openable {
namespace {

using drawing::DrawLegend;
using drawing::Ellipsize;
using drawing::FitBold;
using drawing::kBlack;
using drawing::kGridGrey;
using drawing::kPalette;
using drawing::kPaletteSize;
using drawing::LegendEntry;
using drawing::PutText;
using drawing::PutVerticalText;
using drawing::TextSize;

// ---------------------------------------------------------------------------------------------
// Precision-recall figure.

constexpr int kTitleHeight = 40;
constexpr int kPanelWidth = 700;
constexpr int kPanelHeight = 600;
constexpr int kMarginLeft = 75;
constexpr int kMarginRight = 25;
constexpr int kMarginTop = 50;
constexpr int kMarginBottom = 60;
constexpr int kShift = 4;  // fixed-point bits of curve coordinates
constexpr double kOne = 1 << kShift;

double Clamp01(double v) {
  if (!(v == v)) return 0;  // NaN
  return std::min(1.0, std::max(0.0, v));
}

struct Axes {
  cv::Rect plot;  // plot area: x = recall 0 .. 1, y = precision 1 (top) .. 0 (bottom)

  // Fixed-point (kShift) pixel position of (recall, precision).
  cv::Point Map(double recall, double precision) const {
    const double x = plot.x + Clamp01(recall) * plot.width;
    const double y = plot.y + plot.height - Clamp01(precision) * plot.height;
    return {static_cast<int>(std::lround(x * kOne)), static_cast<int>(std::lround(y * kOne))};
  }
  int TickX(int i) const { return plot.x + static_cast<int>(std::lround(plot.width * i / 10.0)); }
  int TickY(int i) const {
    return plot.y + plot.height - static_cast<int>(std::lround(plot.height * i / 10.0));
  }
};

std::string TickLabel(int i) {
  if (i == 0) return "0";
  if (i == 10) return "1.0";
  return "0." + std::to_string(i);
}

void DrawAxes(cv::Mat3b& img, const Axes& axes, const std::string& panel_title) {
  const cv::Rect& r = axes.plot;
  const int left = r.x, right = r.x + r.width, top = r.y, bottom = r.y + r.height;
  // Grid.
  for (int i = 1; i < 10; ++i) {
    cv::line(img, {axes.TickX(i), top}, {axes.TickX(i), bottom}, kGridGrey, 1);
    cv::line(img, {left, axes.TickY(i)}, {right, axes.TickY(i)}, kGridGrey, 1);
  }
  // Frame, ticks and tick labels.
  cv::rectangle(img, {left, top}, {right, bottom}, kBlack, 1);
  const double tick_scale = 0.45;
  for (int i = 0; i <= 10; ++i) {
    const std::string label = TickLabel(i);
    int baseline = 0;
    const cv::Size s = TextSize(label, tick_scale, 1, &baseline);
    const int x = axes.TickX(i);
    cv::line(img, {x, bottom}, {x, bottom + 5}, kBlack, 1);
    PutText(img, label, {x - s.width / 2, bottom + 9 + s.height}, tick_scale, 1, kBlack);
    const int y = axes.TickY(i);
    cv::line(img, {left - 5, y}, {left, y}, kBlack, 1);
    PutText(img, label, {left - 9 - s.width, y + s.height / 2}, tick_scale, 1, kBlack);
  }
  // Axis labels.
  const double label_scale = 0.6;
  const cv::Size recall_size = TextSize("Recall", label_scale, 1);
  PutText(img, "Recall", {left + r.width / 2 - recall_size.width / 2, bottom + 48}, label_scale, 1,
          kBlack);
  PutVerticalText(img, "Precision", {left - 58, top + r.height / 2}, label_scale, 1);
  // Panel title, centred over the plot area.
  double title_scale = 0;
  int title_thickness = 0;
  FitBold(panel_title, 0.65, 0.45, r.width, &title_scale, &title_thickness);
  const std::string text = Ellipsize(panel_title, title_scale, title_thickness, r.width);
  const cv::Size ts = TextSize(text, title_scale, title_thickness);
  PutText(img, text, {left + r.width / 2 - ts.width / 2, top - 18}, title_scale, title_thickness,
          kBlack);
}

// Step curve through the points in order, starting at (recall 0, precision of the first point):
// each point's precision holds from the previous point's recall to its own (vertical step at the
// previous recall, then horizontal), so the area under the drawing is CurveArea(curve).
void DrawCurve(cv::Mat3b& img, const Axes& axes, const std::vector<CurvePoint>& curve,
               const cv::Scalar& colour) {
  if (curve.empty()) return;
  std::vector<cv::Point> path;
  path.reserve(2 * curve.size() + 1);
  const auto push = [&path](cv::Point p) {
    if (path.empty() || path.back() != p) path.push_back(p);
  };
  double previous_recall = 0;
  push(axes.Map(0, curve.front().precision));
  for (const CurvePoint& p : curve) {
    push(axes.Map(previous_recall, p.precision));
    push(axes.Map(p.recall, p.precision));
    previous_recall = p.recall;
  }
  if (path.size() == 1) {  // a single point at recall 0: a dot
    cv::circle(img, path[0], 2 << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
    return;
  }
  cv::polylines(img, path, false, colour, 2, cv::LINE_AA, kShift);
}

}  // namespace

cv::Mat3b RenderPrPlot(const std::vector<PrSeries>& series, const std::string& title,
                       int vicinity) {
  bool any_able_p = false;
  for (const PrSeries& s : series) any_able_p = any_able_p || !s.able_p.empty();
  const int panels = any_able_p ? 2 : 1;
  cv::Mat3b img(kTitleHeight + kPanelHeight, panels * kPanelWidth, cv::Vec3b(255, 255, 255));

  // Overall title, centred.
  if (!title.empty()) {
    double scale = 0;
    int thickness = 0;
    FitBold(title, 0.8, 0.45, img.cols - 20, &scale, &thickness);
    const std::string text = Ellipsize(title, scale, thickness, img.cols - 20);
    const cv::Size s = TextSize(text, scale, thickness);
    PutText(img, text, {img.cols / 2 - s.width / 2, kTitleHeight / 2 + s.height / 2 + 6}, scale,
            thickness, kBlack);
  }

  for (int panel = 0; panel < panels; ++panel) {
    Axes axes;
    axes.plot = cv::Rect(panel * kPanelWidth + kMarginLeft, kTitleHeight + kMarginTop,
                         kPanelWidth - kMarginLeft - kMarginRight,
                         kPanelHeight - kMarginTop - kMarginBottom);
    const std::string panel_title =
        panel == 0 ? "Per-query best match"
                   : "ABLE-P cells (vicinity " + std::to_string(vicinity) + ")";
    DrawAxes(img, axes, panel_title);
    std::vector<LegendEntry> legend;
    for (std::size_t i = 0; i < series.size(); ++i) {
      const cv::Scalar& colour = kPalette[i % kPaletteSize];
      const std::vector<CurvePoint>& curve = panel == 0 ? series[i].per_query : series[i].able_p;
      // A series without cells (the verified answers of a run, whose cells are its
      // unverified series') is left out of the ABLE-P panel.
      if (panel == 1 && curve.empty()) continue;
      DrawCurve(img, axes, curve, colour);
      std::string suffix;
      if (curve.empty())
        suffix = " (no points)";
      else if (panel == 0)
        suffix = " (AUC " + FormatFixed(CurveArea(curve), 3) + ")";
      else
        suffix = " (AP " + FormatFixed(100.0 * CurveArea(curve), 1) + "%)";
      legend.push_back({series[i].label, suffix, colour});
    }
    DrawLegend(img, axes.plot, legend);
  }
  return img;
}

// ---------------------------------------------------------------------------------------------
// Overlay of the ground truth and the best matches on the matrix.

namespace {

constexpr int kOverlayTarget = 600;  // longer side of the enlarged block, at least
constexpr int kLegendLine = 30;      // height of one line of the legend strip
const cv::Vec3b kTruthTint(255, 128, 0);
const cv::Vec3b kCorrect(0, 200, 0);
const cv::Vec3b kWrong(0, 0, 230);
const cv::Vec3b kRejected(220, 0, 220);  // magenta: apart from green, red and the blue tint
const cv::Vec3b kAccepted(0, 140, 255);  // orange: an answer accepted without ground truth

// Grey level of a normalised value: 255 v rounded, clamped to [0, 255]; NaN is white.
inline std::uint8_t Grey(float v) {
  if (!(v == v)) return 255;
  const float c = std::min(1.0f, std::max(0.0f, v));
  return static_cast<std::uint8_t>(std::lround(255.0f * c));
}

// The legend strip: swatches and texts, flowing onto further lines when `width` is too small.
// With the ground truth (`truth`): its tint and the answers right or wrong; without: the
// accepted answers, not judged.
cv::Mat3b OverlayLegend(int width, bool truth, bool verification) {
  struct Item {
    std::string text;
    bool swatch;
    cv::Vec3b colour;
  };
  std::vector<Item> all;
  if (truth) {
    all = {
        {"ground truth", true, cv::Vec3b(192, 128, 64)},  // the tint over mid grey
        {verification ? "verified, correct" : "accepted, correct", true, kCorrect},
        {verification ? "verified, wrong" : "accepted, wrong", true, kWrong},
    };
  } else {
    all = {{verification ? "verified and accepted (no ground truth: not judged)"
                         : "accepted best match (no ground truth: not judged)",
            true, kAccepted}};
  }
  if (verification) all.push_back({"rejected by verification", true, kRejected});
  all.push_back({"rows: queries, columns: references", false, cv::Vec3b()});
  const double scale = 0.5;
  const int swatch = 14, swatch_gap = 6, item_gap = 22, margin = 10;
  // Lay out: positions (line, x) for each item.
  std::vector<std::pair<int, int>> where;
  int line = 0, x = margin;
  for (const Item& item : all) {
    const int w = (item.swatch ? swatch + swatch_gap : 0) + TextSize(item.text, scale, 1).width;
    if (x > margin && x + w > width - margin) {
      ++line;
      x = margin;
    }
    where.emplace_back(line, x);
    x += w + item_gap;
  }
  cv::Mat3b strip((line + 1) * kLegendLine, width, cv::Vec3b(255, 255, 255));
  const int text_height = TextSize("Ag", scale, 1).height;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const int top = where[i].first * kLegendLine;
    int left = where[i].second;
    const int mid = top + kLegendLine / 2;
    if (all[i].swatch) {
      const cv::Rect r(left, mid - swatch / 2, swatch, swatch);
      cv::rectangle(strip, r, cv::Scalar(all[i].colour), cv::FILLED);
      cv::rectangle(strip, r, cv::Scalar(90, 90, 90), 1);
      left += swatch + swatch_gap;
    }
    PutText(strip, all[i].text, {left, mid + text_height / 2}, scale, 1, kBlack);
  }
  return strip;
}

// A step between labelled frames: 1, 2 or 5 times a power of ten, the smallest that puts at
// most 8 labels along `frames`.
int TickStep(int frames) {
  for (int power = 1;; power *= 10)
    for (int m : {1, 2, 5})
      if (frames <= 8 * m * power) return m * power;
}

// The frame numbers of the block's rows (queries, left) and columns (references, top), every
// TickStep frames, each at the middle of its enlarged cell, with the axes' titles.
void DrawOverlayAxes(cv::Mat3b& img, int rows, int cols, int k) {
  const double scale = 0.4;
  const int left = kOverlayAxisLeft, top = kOverlayAxisTop;
  const cv::Scalar tick(90, 90, 90);
  const int text_h = TextSize("0", scale, 1).height;
  for (int c = 0, step = TickStep(cols); c < cols; c += step) {
    const int x = left + c * k + k / 2;
    cv::line(img, {x, top - 5}, {x, top - 1}, tick, 1);
    const std::string label = std::to_string(c);
    const int w = TextSize(label, scale, 1).width;
    PutText(img, label, {std::max(0, x - w / 2), top - 8}, scale, 1, kBlack);
  }
  for (int q = 0, step = TickStep(rows); q < rows; q += step) {
    const int y = top + q * k + k / 2;
    cv::line(img, {left - 5, y}, {left - 1, y}, tick, 1);
    const std::string label = std::to_string(q);
    const int w = TextSize(label, scale, 1).width;
    PutText(img, label, {left - 8 - w, y + text_h / 2}, scale, 1, kBlack);
  }
  const int title_w = TextSize("reference frame", scale, 1).width;
  PutText(img, "reference frame", {left + (std::min(cols * k, 600) - title_w) / 2, 13}, scale, 1,
          kBlack);
  PutVerticalText(img, "query frame", {9, top + std::min(rows * k, 600) / 2}, scale, 1);
}

}  // namespace

namespace {

// The figure of RenderOverlay: the block in grey with the ground truth tinted when `truth` is
// given, enlarged, with its axes and legend, the cells of `rejected` in magenta, then the
// answers `marks` draws (given the block's image, the enlargement k and how much a mark grows
// on each side).
using DrawMarks = std::function<void(cv::Mat3b& img, int k, int grow)>;
cv::Mat3b DrawOverlay(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                      const GroundTruth* truth, const std::vector<cv::Point>* rejected,
                      const DrawMarks& marks) {
  const int rows = layout.queries, cols = layout.references;
  if (rows <= 0 || cols <= 0 || layout.row_offset < 0 || layout.col_offset < 0 ||
      layout.row_offset + rows > matrix.rows || layout.col_offset + cols > matrix.cols) {
    throw std::logic_error("RenderOverlay: the layout's block (" + std::to_string(rows) + " x " +
                           std::to_string(cols) + " at row " + std::to_string(layout.row_offset) +
                           ", column " + std::to_string(layout.col_offset) +
                           ") is not inside the " + std::to_string(matrix.rows) + " x " +
                           std::to_string(matrix.cols) + " matrix");
  }
  const cv::Mat1f block = matrix(cv::Rect(layout.col_offset, layout.row_offset, cols, rows));

  // One pixel per cell: grey, then the ground truth tinted (50 % blend).
  cv::Mat3b cells(rows, cols);
  for (int q = 0; q < rows; ++q) {
    const float* in = block.ptr<float>(q);
    cv::Vec3b* out = cells.ptr<cv::Vec3b>(q);
    for (int c = 0; c < cols; ++c) {
      const std::uint8_t g = Grey(in[c]);
      out[c] = cv::Vec3b(g, g, g);
    }
  }
  const int truth_rows =
      truth != nullptr ? std::min(rows, static_cast<int>(truth->matches.size())) : 0;
  for (int q = 0; q < truth_rows; ++q) {
    cv::Vec3b* out = cells.ptr<cv::Vec3b>(q);
    for (int c : truth->matches[q]) {
      if (c < 0 || c >= cols) continue;
      cv::Vec3b& p = out[c];
      for (int ch = 0; ch < 3; ++ch)
        p[ch] = static_cast<std::uint8_t>((p[ch] + kTruthTint[ch] + 1) / 2);
    }
  }

  // Nearest-neighbour enlargement by an integer factor.
  const int k = std::max(1, (kOverlayTarget + std::max(rows, cols) - 1) / std::max(rows, cols));
  const int image_w = cols * k, image_h = rows * k;
  const int left = kOverlayAxisLeft, top = kOverlayAxisTop;
  const cv::Mat3b legend = OverlayLegend(left + std::max(image_w, kOverlayTarget), truth != nullptr,
                                         rejected != nullptr);
  cv::Mat3b whole(top + image_h + legend.rows, legend.cols, cv::Vec3b(255, 255, 255));
  DrawOverlayAxes(whole, rows, cols, k);
  // The block's pixels: `img` is a view of them, so that marks are placed in cell units.
  cv::Mat3b img = whole(cv::Rect(left, top, image_w, image_h));
  if (k == 1) {
    cells.copyTo(img);
  } else {
    for (int q = 0; q < rows; ++q) {
      const cv::Vec3b* in = cells.ptr<cv::Vec3b>(q);
      cv::Vec3b* out = img.ptr<cv::Vec3b>(q * k);
      for (int c = 0; c < cols; ++c) std::fill(out + c * k, out + (c + 1) * k, in[c]);
      for (int y = 1; y < k; ++y) std::copy(out, out + image_w, img.ptr<cv::Vec3b>(q * k + y));
    }
  }

  // Marks are the enlarged cell, grown to at least 3 x 3 pixels (and to 5 x 5 and more on very
  // large images, so they stay visible when the image is viewed whole).
  int grow = k >= 3 ? 0 : 1;
  if (k == 1) grow = std::max(grow, std::max(rows, cols) / 1200);
  const cv::Rect image_area(0, 0, image_w, image_h);
  if (rejected != nullptr)  // first, so that an answer at the same cell stays visible
    for (const cv::Point& cell : *rejected) {
      if (cell.x < 0 || cell.x >= cols || cell.y < 0 || cell.y >= rows) continue;
      img(cv::Rect(cell.x * k - grow, cell.y * k - grow, k + 2 * grow, k + 2 * grow) & image_area)
          .setTo(kRejected);
    }
  marks(img, k, grow);

  legend.copyTo(whole(cv::Rect(0, top + image_h, legend.cols, legend.rows)));
  return whole;
}

// Marks query q's answer c in `img` (enlarged k times, marks grown by `grow`).
void Mark(cv::Mat3b& img, int k, int grow, int q, int c, const cv::Vec3b& colour) {
  const cv::Rect mark = cv::Rect(c * k - grow, q * k - grow, k + 2 * grow, k + 2 * grow) &
                        cv::Rect(0, 0, img.cols, img.rows);
  img(mark).setTo(colour);
}

}  // namespace

cv::Mat3b RenderOverlay(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                        const GroundTruth& truth, const PerQueryResult& result,
                        double accept_threshold, const std::vector<cv::Point>* rejected) {
  const int rows = layout.queries, cols = layout.references;
  return DrawOverlay(matrix, layout, &truth, rejected, [&](cv::Mat3b& img, int k, int grow) {
    const int marked = std::min(
        rows, static_cast<int>(
                  std::min({result.best.size(), result.score.size(), result.correct.size()})));
    for (int pass = 0; pass < 2; ++pass) {  // wrong marks last, so a neighbour never hides them
      for (int q = 0; q < marked; ++q) {
        const int c = result.best[q];
        const float d = result.score[q];
        // At the operating point, the answers it accepted (Match_consistency may refuse some
        // below its threshold); else those with a score within the threshold given.
        const bool at_operating_point =
            result.has_operating_point && q < static_cast<int>(result.accepted.size());
        const bool accepted = at_operating_point ? result.accepted[q] != 0 : d <= accept_threshold;
        if (c < 0 || c >= cols || !accepted) continue;
        const bool correct = result.correct[q] != 0;
        if (correct != (pass == 0)) continue;
        Mark(img, k, grow, q, c, correct ? kCorrect : kWrong);
      }
    }
  });
}

cv::Mat3b RenderAnswersOverlay(const cv::Mat1f& matrix, const EvaluationLayout& layout,
                               const std::vector<int>& best,
                               const std::vector<std::uint8_t>& accepted,
                               const std::vector<cv::Point>* rejected) {
  const int rows = layout.queries, cols = layout.references;
  return DrawOverlay(matrix, layout, nullptr, rejected, [&](cv::Mat3b& img, int k, int grow) {
    const int marked = std::min(rows, static_cast<int>(std::min(best.size(), accepted.size())));
    for (int q = 0; q < marked; ++q)
      if (best[q] >= 0 && best[q] < cols && accepted[q]) Mark(img, k, grow, q, best[q], kAccepted);
  });
}

}  // namespace openable
