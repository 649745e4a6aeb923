#include "descriptors/frame_describer.h"

#include <algorithm>
#include <cstddef>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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
  const int cell = descriptor_.InputSize().empty() ? 16 : 1;
  return cv::Size(cell * grid_x_ * panoramas_, cell * grid_y_);
}

void FrameDescriber::Learn(const std::vector<cv::Mat>& images) const {
  std::vector<cv::Mat> patches;
  for (const cv::Mat& image : images)
    for (cv::Mat& p : Patches(image)) patches.push_back(std::move(p));
  descriptor_.Learn(patches);
}

int FrameDescriber::RowType() const { return openable::RowType(descriptor_); }

int FrameDescriber::Channels() const { return descriptor_.Channels(); }

std::vector<cv::Mat> FrameDescriber::Patches(const cv::Mat& image) const {
  if (image.type() != CV_8UC(descriptor_.Channels()))
    throw std::logic_error("FrameDescriber: expected a CV_8UC" +
                           std::to_string(descriptor_.Channels()) + " image for " +
                           descriptor_.Name() + ", got " + cv::typeToString(image.type()));
  const cv::Size minimum = MinimumFrame();
  if (image.cols < minimum.width || image.rows < minimum.height)
    throw std::logic_error("FrameDescriber: frame smaller than the grid");
  const cv::Size input = descriptor_.InputSize();
  std::vector<cv::Mat> patches;
  patches.reserve(static_cast<std::size_t>(grid_x_ * grid_y_ * panoramas_));
  // Sub-panorama s spans columns [floor(s W / n), floor((s + 1) W / n)) (n = 1 for a
  // monocular frame: the whole frame).
  for (int s = 0; s < panoramas_; ++s) {
    const cv::Mat strip =
        image.colRange(s * image.cols / panoramas_, (s + 1) * image.cols / panoramas_);
    for (int gy = 0; gy < grid_y_; ++gy)
      for (int gx = 0; gx < grid_x_; ++gx) {
        const int x0 = gx * strip.cols / grid_x_, x1 = (gx + 1) * strip.cols / grid_x_;
        const int y0 = gy * strip.rows / grid_y_, y1 = (gy + 1) * strip.rows / grid_y_;
        const cv::Mat cell = strip(cv::Range(y0, y1), cv::Range(x0, x1));
        // Area interpolation when shrinking (it averages, avoiding aliasing); linear when a
        // cell is smaller than the patch; none when it has the patch's size.
        cv::Mat patch;
        if (input.empty() || cell.size() == input) {
          patch = cell.clone();
        } else {
          const bool shrink = cell.cols >= input.width && cell.rows >= input.height;
          cv::resize(cell, patch, input, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
        }
        patches.push_back(std::move(patch));
      }
  }
  return patches;
}

void FrameDescriber::Describe(const cv::Mat& image, cv::Mat row) const {
  const std::vector<cv::Mat> patches = Patches(image);
  if (Batched()) {
    DescribePatches(patches, row);
    return;
  }
  const int width = descriptor_.Width();
  for (std::size_t c = 0; c < patches.size(); ++c)
    descriptor_.Describe(
        patches[c], row.colRange(static_cast<int>(c) * width, (static_cast<int>(c) + 1) * width));
}

void FrameDescriber::DescribePatches(const std::vector<cv::Mat>& patches, cv::Mat rows) const {
  const int per_frame = grid_x_ * grid_y_ * panoramas_;
  if (rows.cols != RowWidth() || rows.type() != RowType() ||
      static_cast<std::size_t>(rows.rows) * static_cast<std::size_t>(per_frame) != patches.size())
    throw std::logic_error("FrameDescriber: " + std::to_string(patches.size()) + " patches for " +
                           std::to_string(rows.rows) + " rows");
  // Row r of `rows` holds the descriptor rows of its frame's patches side by side: viewed as
  // (frames x patches) rows of the descriptor's width, it is one row per patch, in order.
  CV_Assert(rows.isContinuous());
  cv::Mat one_per_patch(static_cast<int>(patches.size()), descriptor_.Width(), rows.type(),
                        rows.data);
  const int batch = std::max(1, descriptor_.PreferredBatch());
  for (std::size_t at = 0; at < patches.size(); at += static_cast<std::size_t>(batch)) {
    const std::size_t end = std::min(patches.size(), at + static_cast<std::size_t>(batch));
    const std::vector<cv::Mat> some(patches.begin() + static_cast<std::ptrdiff_t>(at),
                                    patches.begin() + static_cast<std::ptrdiff_t>(end));
    descriptor_.DescribeBatch(some,
                              one_per_patch.rowRange(static_cast<int>(at), static_cast<int>(end)));
  }
}

}  // namespace openable
