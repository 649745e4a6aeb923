// Description of every frame of a source (a folder, a video, stereo pairs), in parallel, with
// the preprocessing of each frame and the descriptor cache.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/image/preprocess.h"
#include "OpenABLE/io/frame_source.h"
#include "descriptors/descriptor.h"
#include "descriptors/frame_describer.h"
#include "matching/distances.h"

namespace openable {

// The distance the rows of `d` are compared with (its DistanceKind as a matching Metric).
inline Metric MetricOf(const Descriptor& d) {
  switch (d.Distance()) {
    case DistanceKind::kHamming:
      return Metric::kHamming;
    case DistanceKind::kL2:
      return Metric::kL2;
    case DistanceKind::kL1:
      break;
  }
  return Metric::kL1;
}

// Descriptors of every frame of a source, and what was skipped.
struct DescribedSequence {
  cv::Mat rows;                      // one row per kept frame
  std::vector<int> kept;             // source index of each row
  std::vector<std::string> skipped;  // names of frames that could not be read (skip mode)
  cv::Size frame_size;               // size of the frames of this source
};

// Rows kept from earlier runs (descriptor_cache.h). Both calls are made from several threads.
class RowCache {
 public:
  virtual ~RowCache() = default;
  // Fills `row` (1 x RowWidth(), RowType()) and the size of the frame as read when frame i of
  // `source` is cached; false otherwise (also when the frame's file cannot be read).
  virtual bool Lookup(const FrameSource& source, int i, cv::Mat row, cv::Size* frame_size) = 0;
  // Keeps the row of frame i, described from a frame of `frame_size`.
  virtual void Store(const FrameSource& source, int i, const cv::Mat& row, cv::Size frame_size) = 0;
};

struct DescribeOptions {
  int threads = 0;               // 0 = all cores
  bool skip_unreadable = false;  // false: the first unreadable frame is an InputError
  bool show_images = false;      // show each frame in a window (forces one thread)
  std::string key;               // config key naming the source, prefixed to errors
  RowCache* cache = nullptr;     // rows of frames described before; not used with show_images
                                 // or sources without ParallelReads (videos)
  // How each frame is prepared (OpenABLE/image/preprocess.h): noise added before grey
  // conversion (seeded from noise.seed, noise_stream and the frame's index), the grey image or
  // Eq. 6's, side-window fusion of it.
  PreprocessOptions preprocess;
  int noise_stream = 0;  // traversal index: 0 Images_path, 1 Images_path_2
  // `source` is a share of a traversal (a run spread over processes, OpenABLE/cluster/cluster.h):
  // its frame 0 is frame `share_first` of the traversal (the noise of a frame is seeded from
  // that index), and a share whose frames are all skipped is not an error here (the run checks
  // the whole traversal).
  bool share = false;
  int share_first = 0;
};

// For a descriptor that learns before it describes (FrameDescriber::Learns: DenseVLAD's
// vocabulary): reads `frames` frames evenly spread over `source` (the reference traversal),
// converts them as describing does, and learns from them. Unreadable frames are left out.
// Returns the frames learnt from. Throws InputError when the descriptor cannot learn from them.
int LearnFromSource(const FrameSource& source, const FrameDescriber& describer,
                    const DescribeOptions& options, int frames);

// Reads and describes every frame of `source` (in parallel when the source allows it).
// `progress(done, total)` is called from one thread at a time. Throws InputError naming the
// frame when a frame cannot be read (unless skipping), when frames differ in size, or when
// every frame was skipped.
DescribedSequence DescribeSequence(const FrameSource& source, const FrameDescriber& describer,
                                   const DescribeOptions& options,
                                   const std::function<void(int, int)>& progress = {});

// Several descriptors of every frame of `source`, each frame read (decoded) and converted once
// for all of them: one result per descriptor, with the same frames kept and skipped. `caches`
// holds one cache (or nullptr) per descriptor; options.cache is not used. A frame is read only
// when a descriptor's cache lacks its row. Errors and threads as DescribeSequence.
std::vector<DescribedSequence> DescribeSequences(
    const FrameSource& source, const std::vector<const FrameDescriber*>& describers,
    const std::vector<RowCache*>& caches, const DescribeOptions& options,
    const std::function<void(int, int)>& progress = {});

}  // namespace openable
