// Description of whole frames: the global and grid schemes of OpenABLE, over any descriptor.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/robustness.h"
#include "descriptors/descriptor.h"

namespace openable {

enum class DescriptionType { kGlobal = 0, kGrid = 1 };

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
  FrameDescriber(const Descriptor& descriptor, DescriptionType type, int grid_x = 1,
                 int grid_y = 1, int panoramas = 1);
  // Elements per row (descriptor width x cells x sub-panoramas) and their CV type (CV_8U or
  // CV_32F).
  int RowWidth() const;
  int RowType() const;
  // Smallest frame Describe accepts: (grid_x * panoramas) x grid_y pixels.
  cv::Size MinimumFrame() const;
  // Channels of the image Describe takes: the descriptor's (1 grey; 2 grey + disparity for
  // D-LDB, whose cells are then 2-channel: LDB(grey cell) ++ LDB(disparity cell)).
  int Channels() const;
  // Describes `image` (CV_8UC(Channels()), at least MinimumFrame() pixels) into `row`
  // (1 x RowWidth(), RowType()). Every channel of a cell is resized alike. Thread-safe.
  // Throws std::logic_error on another type or a smaller image.
  void Describe(const cv::Mat& image, cv::Mat row) const;

 private:
  const Descriptor& descriptor_;
  DescriptionType type_;
  int grid_x_, grid_y_;
  int panoramas_;
};

// Descriptors of every frame of a source, and what was skipped.
struct DescribedSequence {
  cv::Mat rows;                          // one row per kept frame
  std::vector<int> kept;                 // source index of each row
  std::vector<std::string> skipped;      // names of frames that could not be read (skip mode)
  cv::Size frame_size;                   // size of the frames of this source
};

// Rows kept from earlier runs (descriptor_cache.h). Both calls are made from several threads.
class RowCache {
 public:
  virtual ~RowCache() = default;
  // Fills `row` (1 x RowWidth(), RowType()) and the size of the frame as read when frame i of
  // `source` is cached; false otherwise (also when the frame's file cannot be read).
  virtual bool Lookup(const FrameSource& source, int i, cv::Mat row, cv::Size* frame_size) = 0;
  // Keeps the row of frame i, described from a frame of `frame_size`.
  virtual void Store(const FrameSource& source, int i, const cv::Mat& row,
                     cv::Size frame_size) = 0;
};

struct DescribeOptions {
  int threads = 0;               // 0 = all cores
  bool skip_unreadable = false;  // false: the first unreadable frame is an InputError
  bool show_images = false;      // show each frame in a window (forces one thread)
  bool illumination_invariance = false;  // describe IlluminationInvariant(frame, alpha), not grey
  double alpha = 0.47;
  std::string key;               // config key naming the source, prefixed to errors
  RowCache* cache = nullptr;     // rows of frames described before; not used with show_images
                                 // or sources without ParallelReads (videos)
  // Robustness (OpenABLE/robustness.h): noise added to each frame before grey conversion
  // (off unless options set), seeded from noise.seed, noise_stream and the frame's index;
  // side-window fusion of the grey image with these radii (empty = off) before description.
  NoiseOptions noise;
  int noise_stream = 0;          // traversal index: 0 Images_path, 1 Images_path_2
  std::vector<int> side_window_radii;
};

// Reads and describes every frame of `source` (in parallel when the source allows it).
// `progress(done, total)` is called from one thread at a time. Throws InputError naming the
// frame when a frame cannot be read (unless skipping), when frames differ in size, or when
// every frame was skipped.
DescribedSequence DescribeSequence(const FrameSource& source, const FrameDescriber& describer,
                                   const DescribeOptions& options,
                                   const std::function<void(int, int)>& progress = {});

}  // namespace openable
