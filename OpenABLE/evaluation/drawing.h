// Drawing helpers shared by the figures (evaluation/plots.cc, snaps/plot.cc): the house style
// of OpenABLE's figures, drawn with OpenCV only (Hershey simplex text, anti-aliased lines, the
// Okabe-Ito palette, a framed legend box).
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace openable::drawing {

inline constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
inline const cv::Scalar kBlack(0, 0, 0);
inline const cv::Scalar kWhite(255, 255, 255);
inline const cv::Scalar kGridGrey(225, 225, 225);
inline const cv::Scalar kFrameGrey(160, 160, 160);

// Okabe-Ito, BGR: blue, orange, bluish green, vermillion, reddish purple, sky blue, black,
// yellow (yellow last: it is the weakest on white).
inline const cv::Scalar kPalette[] = {
    {178, 114, 0},   {0, 159, 230},  {115, 158, 0}, {0, 94, 213},
    {167, 121, 204}, {233, 180, 86}, {0, 0, 0},     {66, 228, 240},
};
inline constexpr int kPaletteSize = static_cast<int>(sizeof(kPalette) / sizeof(kPalette[0]));

// Size of `text` in kFont; `baseline` receives the descent below the baseline.
cv::Size TextSize(const std::string& text, double scale, int thickness, int* baseline = nullptr);

// Anti-aliased kFont text with its baseline starting at `baseline_left`.
void PutText(cv::Mat3b& img, const std::string& text, cv::Point baseline_left, double scale,
             int thickness, const cv::Scalar& colour);

// Largest scale <= `scale` (down to `min_scale`, steps of 0.05) at which `text` fits in
// `max_width`.
double FitScale(const std::string& text, double scale, double min_scale, int thickness,
                int max_width);

// Bold (thickness 2) text at `scale` if it fits in `max_width` at a scale >= 0.6; else thin text
// at a scale >= `min_scale` (thick Hershey strokes clog at small scales).
void FitBold(const std::string& text, double scale, double min_scale, int max_width,
             double* fitted_scale, int* thickness);

// `text` shortened with "..." until it fits in `max_width` at `scale`.
std::string Ellipsize(const std::string& text, double scale, int thickness, int max_width);

// Black text rotated by 90 degrees counter-clockwise (reads bottom to top), centred on `centre`,
// drawn over a light background.
void PutVerticalText(cv::Mat3b& img, const std::string& text, cv::Point centre, double scale,
                     int thickness);

struct LegendEntry {
  std::string label;   // shortened with "..." when the box would not fit in the plot area
  std::string suffix;  // " (AUC 0.612)", kept whole
  cv::Scalar colour;
  int thickness = 2;  // of the line sample
};

enum class LegendCorner { kLowerLeft, kUpperLeft, kUpperRight, kLowerRight };

// Legend box (white, grey frame) inside `plot`, 10 px from the given corner: one row per entry,
// a line sample in the entry's colour then its text; rows shrink when there are many.
void DrawLegend(cv::Mat3b& img, const cv::Rect& plot, const std::vector<LegendEntry>& entries,
                LegendCorner corner = LegendCorner::kLowerLeft);

}  // namespace openable::drawing
