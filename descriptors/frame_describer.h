// Description of whole frames: the global and grid schemes of OpenABLE, and the sub-panoramas
// of ABLE-P, over any descriptor of the registry.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/enum_names.h"
#include "descriptors/descriptor.h"

namespace openable {

enum class DescriptionType { kGlobal = 0, kGrid = 1 };
OPENABLE_ENUM_NAMES(DescriptionType, "global", "grid")

// How a frame is cut before each part is described (keys Description_type, Grid_x, Grid_y,
// Panoramas).
struct DescriptionOptions {
  DescriptionType type = DescriptionType::kGlobal;  // global: the whole frame; grid: cells
  int grid_x = 2;                                   // grid cells across (type kGrid), 1..64
  int grid_y = 2;                                   // grid cells down (type kGrid), 1..64
  int panoramas = 4;  // sub-panoramas of a panoramic frame, 1..64 (used for panoramic cameras)

  // Throws InputError naming the key (Grid_x, Grid_y, Panoramas), the value and the range.
  void Check() const;
};

// Turns a grey frame into one descriptor row.
//  - Global: the frame is resized to the descriptor's patch (area interpolation) and described
//    at its centre, as ABLE does.
//  - Grid: the frame is cut into grid_x x grid_y cells (cell c spans [floor(c W / n),
//    floor((c+1) W / n))), each cell is resized to the patch and described at its centre, and
//    the rows are concatenated in row-major cell order. (The original placed grid keypoints on
//    the full-size frame; resizing each cell works for every descriptor at any frame size and
//    keeps the patch the descriptor was designed for.)
// With panoramas = n > 1 (Camera_type 2, ABLE-P Eq. 1) the frame is first cut into n
// equal-width vertical strips (strip s spans [floor(s W / n), floor((s+1) W / n))), each strip
// is described as above (global or grid) and the n rows are concatenated in strip order.
class FrameDescriber {
 public:
  FrameDescriber(const Descriptor& descriptor, DescriptionType type, int grid_x = 1, int grid_y = 1,
                 int panoramas = 1);
  // Elements per row (descriptor width x cells x sub-panoramas) and their CV type (CV_8U or
  // CV_32F).
  int RowWidth() const;
  int RowType() const;
  // Smallest frame Describe accepts: (grid_x * panoramas) x grid_y pixels; 16 times as many
  // for a descriptor that takes patches of any size (DenseVLAD's cells are at least 16 x 16).
  cv::Size MinimumFrame() const;
  // Channels of the image Describe takes: the descriptor's (1 grey; 2 grey + disparity for
  // D-LDB, whose cells are then 2-channel: LDB(grey cell) ++ LDB(disparity cell)).
  int Channels() const;
  // Describes `image` (CV_8UC(Channels()), at least MinimumFrame() pixels) into `row`
  // (1 x RowWidth(), RowType()). Every channel of a cell is resized alike. Thread-safe.
  // Throws std::logic_error on another type or a smaller image.
  void Describe(const cv::Mat& image, cv::Mat row) const;

  // Whether frames are best described several at once (a network: Descriptor::PreferredBatch
  // above 1): then the caller cuts each frame's patches (Patches, in parallel) and describes
  // the patches of many frames in one call (DescribePatches).
  bool Batched() const { return descriptor_.PreferredBatch() > 1; }
  // Whether the descriptor learns from frames before describing (Descriptor::Learns).
  bool Learns() const { return descriptor_.Learns(); }
  int LearnFrames() const { return descriptor_.LearnFrames(); }
  // Learns from the patches of `images` (as Describe takes them, frames spread over the
  // reference traversal): Descriptor::Learn. Call before any Describe.
  void Learn(const std::vector<cv::Mat>& images) const;
  // The rows of traversal `t` when they are given, not described (Descriptor::GivenRows).
  const cv::Mat* GivenRows(int t) const { return descriptor_.GivenRows(t); }
  // The descriptor's Fingerprint (a network's weights): part of the descriptor cache's key.
  std::string Fingerprint() const { return descriptor_.Fingerprint(); }
  // Frames whose patches make about one batch.
  int PreferredBatchOfFrames() const {
    const int per_frame = grid_x_ * grid_y_ * panoramas_;
    return descriptor_.PreferredBatch() > per_frame ? descriptor_.PreferredBatch() / per_frame : 1;
  }
  // The patches Describe would describe for `image`, in row order (sub-panorama, then cell),
  // each resized to the descriptor's input. Thread-safe; throws as Describe.
  std::vector<cv::Mat> Patches(const cv::Mat& image) const;
  // Describes the patches of several frames (Patches of each, concatenated) into `rows`
  // (frames x RowWidth()), Descriptor::PreferredBatch patches at a time.
  void DescribePatches(const std::vector<cv::Mat>& patches, cv::Mat rows) const;

 private:
  const Descriptor& descriptor_;
  DescriptionType type_;
  int grid_x_, grid_y_;
  int panoramas_;
};

}  // namespace openable
