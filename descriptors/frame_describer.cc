#include "descriptors/frame_describer.h"

#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "OpenABLE/base/error.h"

namespace openable {

void DescriptionOptions::Check() const {
  auto range = [](const char* key, int value, int lo, int hi) {
    if (value < lo || value > hi)
      throw InputError(std::string(key) + ": " + std::to_string(value) +
                       " is out of range; expected an integer in [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
  };
  range("Grid_x", grid_x, 1, 64);
  range("Grid_y", grid_y, 1, 64);
  range("Panoramas", panoramas, 1, 64);
}

FrameDescriber::FrameDescriber(const Descriptor& descriptor, DescriptionType type, int grid_x,
                               int grid_y, int panoramas)
    : descriptor_(descriptor),
      type_(type),
      grid_x_(type == DescriptionType::kGrid ? grid_x : 1),
      grid_y_(type == DescriptionType::kGrid ? grid_y : 1),
      panoramas_(panoramas) {
  if (grid_x_ < 1 || grid_y_ < 1) throw std::logic_error("FrameDescriber: grid below 1x1");
  if (panoramas_ < 1) throw std::logic_error("FrameDescriber: fewer than 1 sub-panorama");
}

int FrameDescriber::RowWidth() const {
  return descriptor_.Width() * grid_x_ * grid_y_ * panoramas_;
}
cv::Size FrameDescriber::MinimumFrame() const {
  return cv::Size(grid_x_ * panoramas_, grid_y_);
}

int FrameDescriber::RowType() const { return openable::RowType(descriptor_); }

int FrameDescriber::Channels() const { return descriptor_.Channels(); }

void FrameDescriber::Describe(const cv::Mat& gray, cv::Mat row) const {
  if (gray.type() != CV_8UC(descriptor_.Channels()))
    throw std::logic_error("FrameDescriber: expected a CV_8UC" +
                           std::to_string(descriptor_.Channels()) + " image for " +
                           descriptor_.Name() + ", got " + cv::typeToString(gray.type()));
  if (gray.cols < grid_x_ * panoramas_ || gray.rows < grid_y_)
    throw std::logic_error("FrameDescriber: frame smaller than the grid");
  const int p = descriptor_.PatchSize();
  const int width = descriptor_.Width();
  const int cells = grid_x_ * grid_y_;
  cv::Mat patch;
  // Sub-panorama s spans columns [floor(s W / n), floor((s + 1) W / n)) (n = 1 for a
  // monocular frame: the whole frame).
  for (int s = 0; s < panoramas_; ++s) {
    const cv::Mat strip =
        gray.colRange(s * gray.cols / panoramas_, (s + 1) * gray.cols / panoramas_);
    for (int gy = 0; gy < grid_y_; ++gy)
      for (int gx = 0; gx < grid_x_; ++gx) {
        const int x0 = gx * strip.cols / grid_x_, x1 = (gx + 1) * strip.cols / grid_x_;
        const int y0 = gy * strip.rows / grid_y_, y1 = (gy + 1) * strip.rows / grid_y_;
        const cv::Mat cell = strip(cv::Range(y0, y1), cv::Range(x0, x1));
        // Area interpolation when shrinking (it averages, avoiding aliasing); linear when a
        // cell is smaller than the patch.
        const bool shrink = cell.cols >= p && cell.rows >= p;
        cv::resize(cell, patch, cv::Size(p, p), 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
        const int c = s * cells + gy * grid_x_ + gx;
        descriptor_.Describe(patch, row.colRange(c * width, (c + 1) * width));
      }
  }
}

}  // namespace openable
