// Drawing helpers shared by the figures: see drawing.h.
#include "OpenABLE/evaluation/drawing.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace openable::drawing {

cv::Size TextSize(const std::string& text, double scale, int thickness, int* baseline) {
  int b = 0;
  const cv::Size s = cv::getTextSize(text, kFont, scale, thickness, &b);
  if (baseline != nullptr) *baseline = b;
  return s;
}

void PutText(cv::Mat3b& img, const std::string& text, cv::Point baseline_left, double scale,
             int thickness, const cv::Scalar& colour) {
  cv::putText(img, text, baseline_left, kFont, scale, colour, thickness, cv::LINE_AA);
}

// Largest scale <= `scale` (down to `min_scale`) at which `text` fits in `max_width`.
double FitScale(const std::string& text, double scale, double min_scale, int thickness,
                int max_width) {
  while (scale > min_scale && TextSize(text, scale, thickness).width > max_width) scale -= 0.05;
  return std::max(scale, min_scale);
}

// Bold (thickness 2) text at `scale` if it fits in `max_width` at a scale >= 0.6; else thin text
// at a scale >= `min_scale` (thick Hershey strokes clog at small scales).
void FitBold(const std::string& text, double scale, double min_scale, int max_width,
             double* fitted_scale, int* thickness) {
  *thickness = 2;
  *fitted_scale = FitScale(text, scale, 0.6, 2, max_width);
  if (TextSize(text, *fitted_scale, 2).width <= max_width) return;
  *thickness = 1;
  *fitted_scale = FitScale(text, 0.6, min_scale, 1, max_width);
}

// `text` shortened with "..." until it fits in `max_width` at `scale`.
std::string Ellipsize(const std::string& text, double scale, int thickness, int max_width) {
  if (TextSize(text, scale, thickness).width <= max_width) return text;
  std::string t = text;
  while (!t.empty() && TextSize(t + "...", scale, thickness).width > max_width) t.pop_back();
  return t + "...";
}

// Text rotated by 90 degrees counter-clockwise (reads bottom to top), centred on `centre`.
void PutVerticalText(cv::Mat3b& img, const std::string& text, cv::Point centre, double scale,
                     int thickness) {
  int baseline = 0;
  const cv::Size s = TextSize(text, scale, thickness, &baseline);
  cv::Mat3b label(s.height + baseline + 4, s.width + 4, cv::Vec3b(255, 255, 255));
  PutText(label, text, {2, 2 + s.height}, scale, thickness, kBlack);
  cv::Mat3b rotated;
  cv::rotate(label, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  cv::Rect where(centre.x - rotated.cols / 2, centre.y - rotated.rows / 2, rotated.cols,
                 rotated.rows);
  const cv::Rect clipped = where & cv::Rect(0, 0, img.cols, img.rows);
  if (clipped.empty()) return;
  cv::Mat target = img(clipped);
  const cv::Mat source =
      rotated(cv::Rect(clipped.x - where.x, clipped.y - where.y, clipped.width, clipped.height));
  cv::min(target, source, target);  // dark text over whatever is there (white)
}

void DrawLegend(cv::Mat3b& img, const cv::Rect& plot, const std::vector<LegendEntry>& entries,
                LegendCorner corner) {
  if (entries.empty()) return;
  const cv::Rect& r = plot;
  const int pad = 8, sample = 28, gap = 8;
  const int max_text_width = r.width - 20 - 2 * pad - sample - gap;
  // Smaller rows when there are many series, so the box stays inside the plot area.
  double scale = 0.48;
  int row = 22;
  const int rows = static_cast<int>(entries.size());
  if (rows * row + 2 * pad > r.height - 20) {
    row = std::max(12, (r.height - 20 - 2 * pad) / rows);
    scale = std::max(0.3, scale * row / 22.0);
  }
  std::vector<std::string> texts;
  int text_width = 0;
  for (const LegendEntry& e : entries) {
    const int suffix_width = TextSize(e.suffix, scale, 1).width;
    texts.push_back(Ellipsize(e.label, scale, 1, std::max(0, max_text_width - suffix_width)) +
                    e.suffix);
    text_width = std::max(text_width, TextSize(texts.back(), scale, 1).width);
  }
  const int width = 2 * pad + sample + gap + text_width;
  const int height = 2 * pad + rows * row - (row - TextSize("Ag", scale, 1).height) + 4;
  const bool left = corner == LegendCorner::kLowerLeft || corner == LegendCorner::kUpperLeft;
  const bool top = corner == LegendCorner::kUpperLeft || corner == LegendCorner::kUpperRight;
  const cv::Rect box(left ? r.x + 10 : r.x + r.width - 10 - width,
                     top ? r.y + 10 : r.y + r.height - 10 - height, width, height);
  cv::rectangle(img, box, kWhite, cv::FILLED);
  cv::rectangle(img, box, kFrameGrey, 1);
  const int text_height = TextSize("Ag", scale, 1).height;
  for (int i = 0; i < rows; ++i) {
    const int baseline_y = box.y + pad + i * row + text_height + 1;
    const int mid_y = baseline_y - text_height / 2;
    cv::line(img, {box.x + pad, mid_y}, {box.x + pad + sample, mid_y}, entries[i].colour,
             entries[i].thickness, cv::LINE_AA);
    PutText(img, texts[i], {box.x + pad + sample + gap, baseline_y}, scale, 1, kBlack);
  }
}

}  // namespace openable::drawing
