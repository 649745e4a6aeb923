// Top view of trajectories: see plot.h.
#include "OpenABLE/snaps/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/drawing.h"

namespace openable::snaps {
namespace {

using drawing::DrawLegend;
using drawing::Ellipsize;
using drawing::FitBold;
using drawing::kBlack;
using drawing::kGridGrey;
using drawing::kPalette;
using drawing::LegendCorner;
using drawing::LegendEntry;
using drawing::PutText;
using drawing::PutVerticalText;
using drawing::TextSize;

constexpr int kShift = 4;  // fixed-point bits of drawn coordinates
constexpr double kOne = 1 << kShift;
const cv::Scalar kTruthColour = kPalette[6];      // black
const cv::Scalar kInputColour = kPalette[3];      // vermillion
const cv::Scalar kCorrectedColour = kPalette[0];  // blue
const cv::Scalar kLoopColour(190, 140, 225);      // light reddish purple

// Tick step: 1, 2 or 5 x 10^k, the smallest giving at most `max_ticks` intervals over `range`.
double NiceStep(double range, int max_ticks) {
  if (!(range > 0)) return 1;
  const double raw = range / max_ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= raw) return m * power;
  }
  return 10 * power;
}

std::string TickLabel(double v, double step) {
  const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::string s = FormatFixed(v, decimals);
  if (s == "-0") s = "0";
  return s;
}

struct Frame {
  cv::Rect plot;
  double x0 = 0, y0 = 0;  // data coordinates of the plot's lower left corner
  double pixels_per_metre = 1;
  cv::Point2d Pixel(double x, double y) const {
    return {plot.x + (x - x0) * pixels_per_metre,
            plot.y + plot.height - (y - y0) * pixels_per_metre};
  }
  cv::Point Fixed(double x, double y) const {
    const cv::Point2d p = Pixel(x, y);
    return {static_cast<int>(std::lround(p.x * kOne)), static_cast<int>(std::lround(p.y * kOne))};
  }
};

}  // namespace

cv::Mat3b RenderTrajectories(const TrajectoryPlot& plot) {
  if (plot.input == nullptr) throw std::logic_error("RenderTrajectories: no input trajectory");
  int vertical = 0;
  if (plot.axes == "xz") {
    vertical = 2;
  } else if (plot.axes == "xy") {
    vertical = 1;
  } else {
    throw std::logic_error("RenderTrajectories: axes \"" + plot.axes + "\"; expected xz or xy");
  }
  const Trajectory* loop_source = plot.corrected != nullptr ? plot.corrected : plot.input;
  for (const LoopPair& l : plot.loops) {
    if (l.query < 0 || l.query >= loop_source->Size() || l.reference < 0 ||
        l.reference >= loop_source->Size()) {
      throw std::logic_error("RenderTrajectories: loop index out of range");
    }
  }
  const int size = std::max(300, plot.size);
  cv::Mat3b img(size, size, cv::Vec3b(255, 255, 255));

  // Layout: title band, plot area with room for tick labels and axis labels.
  const int title_height = 50, left = 90, right = 30, bottom = 70;
  const cv::Rect area(left, title_height, size - left - right, size - title_height - bottom);

  // Data range over every trajectory drawn, 4 % padding, equal scale on both axes.
  double min_x = std::numeric_limits<double>::infinity(), max_x = -min_x;
  double min_y = min_x, max_y = -min_x;
  const auto extend = [&](const Trajectory* t) {
    if (t == nullptr) return;
    for (const Eigen::Isometry3d& p : t->poses) {
      min_x = std::min(min_x, p.translation().x());
      max_x = std::max(max_x, p.translation().x());
      min_y = std::min(min_y, p.translation()(vertical));
      max_y = std::max(max_y, p.translation()(vertical));
    }
  };
  extend(plot.truth);
  extend(plot.input);
  extend(plot.corrected);
  if (!std::isfinite(min_x)) min_x = max_x = min_y = max_y = 0;
  double span_x = std::max(max_x - min_x, 1.0), span_y = std::max(max_y - min_y, 1.0);
  span_x *= 1.08;
  span_y *= 1.08;
  Frame frame;
  frame.plot = area;
  frame.pixels_per_metre = std::min(area.width / span_x, area.height / span_y);
  frame.x0 = 0.5 * (min_x + max_x) - 0.5 * area.width / frame.pixels_per_metre;
  frame.y0 = 0.5 * (min_y + max_y) - 0.5 * area.height / frame.pixels_per_metre;
  const double x1 = frame.x0 + area.width / frame.pixels_per_metre;
  const double y1 = frame.y0 + area.height / frame.pixels_per_metre;

  // Grid, frame, ticks (the same step on both axes).
  const double step = NiceStep(std::max(area.width, area.height) / frame.pixels_per_metre, 10);
  const double tick_scale = 0.45;
  for (double v = std::ceil(frame.x0 / step) * step; v <= x1; v += step) {
    const int x = static_cast<int>(std::lround(frame.Pixel(v, 0).x));
    cv::line(img, {x, area.y}, {x, area.y + area.height}, kGridGrey, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 5}, kBlack, 1);
    const std::string label = TickLabel(v, step);
    const cv::Size s = TextSize(label, tick_scale, 1);
    PutText(img, label, {x - s.width / 2, area.y + area.height + 9 + s.height}, tick_scale, 1,
            kBlack);
  }
  for (double v = std::ceil(frame.y0 / step) * step; v <= y1; v += step) {
    const int y = static_cast<int>(std::lround(frame.Pixel(0, v).y));
    cv::line(img, {area.x, y}, {area.x + area.width, y}, kGridGrey, 1);
    cv::line(img, {area.x - 5, y}, {area.x, y}, kBlack, 1);
    const std::string label = TickLabel(v, step);
    const cv::Size s = TextSize(label, tick_scale, 1);
    PutText(img, label, {area.x - 9 - s.width, y + s.height / 2}, tick_scale, 1, kBlack);
  }
  const std::string vertical_name = plot.axes == "xz" ? "z [m]" : "y [m]";
  const cv::Size xs = TextSize("x [m]", 0.6, 1);
  PutText(img, "x [m]", {area.x + area.width / 2 - xs.width / 2, area.y + area.height + 50}, 0.6, 1,
          kBlack);
  PutVerticalText(img, vertical_name, {area.x - 68, area.y + area.height / 2}, 0.6, 1);

  // Content, clipped to the plot area.
  cv::Mat3b canvas = img(area);
  Frame local = frame;
  local.plot = cv::Rect(0, 0, area.width, area.height);
  if (!plot.loops.empty()) {
    for (const LoopPair& l : plot.loops) {
      const Eigen::Vector3d& a = loop_source->poses[l.query].translation();
      const Eigen::Vector3d& b = loop_source->poses[l.reference].translation();
      cv::line(canvas, local.Fixed(a.x(), a(vertical)), local.Fixed(b.x(), b(vertical)),
               kLoopColour, 1, cv::LINE_AA, kShift);
    }
  }
  std::vector<cv::Point2d> all_points;  // for the legend's placement
  const auto draw = [&](const Trajectory* t, const cv::Scalar& colour) {
    if (t == nullptr || t->poses.empty()) return;
    std::vector<cv::Point> path;
    path.reserve(t->poses.size());
    for (const Eigen::Isometry3d& p : t->poses) {
      const cv::Point q = local.Fixed(p.translation().x(), p.translation()(vertical));
      if (path.empty() || path.back() != q) path.push_back(q);
      all_points.push_back(local.Pixel(p.translation().x(), p.translation()(vertical)));
    }
    cv::polylines(canvas, path, false, colour, 2, cv::LINE_AA, kShift);
    cv::circle(canvas, path.front(), 5 << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
  };
  draw(plot.truth, kTruthColour);
  draw(plot.input, kInputColour);
  draw(plot.corrected, kCorrectedColour);
  cv::rectangle(img, area, kBlack, 1);

  // Legend in the emptiest corner (fewest points within 40 % x 25 % of the plot area).
  std::vector<LegendEntry> legend;
  if (plot.truth != nullptr) legend.push_back({plot.truth_label, "", kTruthColour});
  legend.push_back({plot.input_label, "", kInputColour});
  if (plot.corrected != nullptr) legend.push_back({plot.corrected_label, "", kCorrectedColour});
  if (!plot.loops.empty()) {
    legend.push_back(
        {"loop pairs", " (" + std::to_string(plot.loops.size()) + ")", kLoopColour, 1});
  }
  const std::array<LegendCorner, 4> corners = {LegendCorner::kUpperLeft, LegendCorner::kUpperRight,
                                               LegendCorner::kLowerLeft, LegendCorner::kLowerRight};
  LegendCorner best = LegendCorner::kUpperLeft;
  long best_count = std::numeric_limits<long>::max();
  const double w = 0.4 * area.width, h = 0.25 * area.height;
  for (const LegendCorner c : corners) {
    const bool is_left = c == LegendCorner::kUpperLeft || c == LegendCorner::kLowerLeft;
    const bool is_top = c == LegendCorner::kUpperLeft || c == LegendCorner::kUpperRight;
    const cv::Rect2d box(is_left ? 0 : area.width - w, is_top ? 0 : area.height - h, w, h);
    long count = 0;
    for (const cv::Point2d& p : all_points) count += box.contains(p) ? 1 : 0;
    if (count < best_count) {
      best_count = count;
      best = c;
    }
  }
  DrawLegend(img, area, legend, best);

  // Title, centred.
  if (!plot.title.empty()) {
    double scale = 0;
    int thickness = 0;
    FitBold(plot.title, 0.8, 0.45, img.cols - 20, &scale, &thickness);
    const std::string text = Ellipsize(plot.title, scale, thickness, img.cols - 20);
    const cv::Size s = TextSize(text, scale, thickness);
    PutText(img, text, {img.cols / 2 - s.width / 2, title_height / 2 + s.height / 2 + 4}, scale,
            thickness, kBlack);
  }
  return img;
}

}  // namespace openable::snaps
