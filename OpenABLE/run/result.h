// What a run computes (ComputeRun, pipeline.h): its traversals, its matrices, its matches
// and its timings; what verification, the evaluation and the outputs of a run take.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "matching/bounded.h"
#include "matching/distances.h"

namespace openable {

// One traversal of the run (a folder or a video) and the rows it holds in the matrix.
struct Traversal {
  std::string key;                   // config key it came from ("Images_path", ...)
  std::string path;                  // its folder or video
  int first_row = 0;                 // its first row (and column) in the matrix
  int frames = 0;                    // rows it holds
  std::vector<std::string> names;    // frame name of each row (file path or video#index)
  std::vector<double> times;         // seconds of each row (ROS bags); empty: no times
  std::vector<std::string> skipped;  // frames skipped as unreadable (Skip_unreadable 1)
  cv::Size frame_size;
};

struct RunTimings {
  double describe_seconds = 0;  // reading and describing every frame (wall time)
  double match_seconds = 0;     // pairwise distances (wall time)
  double sequence_seconds = 0;  // sequence sums, normalisation and threshold
  double evaluate_seconds = 0;  // evaluation against ground truth (when asked for)
  double export_seconds = 0;    // encoding and writing the outputs
  double total_seconds = 0;
  int frames = 0;          // frames described
  std::int64_t pairs = 0;  // distinct pairs of frames compared
};

// One descriptor of a run (several when Image_descriptor fuses them).
struct RunDescriptor {
  std::string name;   // registry name
  int row_width = 0;  // elements per frame descriptor
  Metric metric = Metric::kHamming;
};

struct RunResult {
  std::vector<Traversal> traversals;       // in matrix order
  std::string descriptor;                  // registry name, or the fused names joined by "+"
  std::vector<RunDescriptor> descriptors;  // each descriptor (one unless fused)
  std::vector<double> fusion_weights;      // fused: the weight of each descriptor's matrix
  std::string camera;                      // camera and preprocessing, one line ("monocular, grey")
  cv::Mat1f normalized;                    // M' of Eq. 5 (N x N over the concatenated traversals)
  float max_distance = 0;                  // max(M), the divisor of Eq. 5
  // Cells of `normalized` that hold +inf: sequences skipped at a traversal's start
  // (Sequence_partial skip); never a best match, exported as documented in WriteOutputs.
  std::int64_t empty_cells = 0;
  cv::Mat1b thresholded;  // M'' of Eq. 9; empty when Threshold is -1
  // Match_threshold >= 0: queries of the evaluated block with a best match, and those whose
  // best match's score (Match_score) is <= Match_threshold.
  int answered_queries = 0, accepted_queries = -1;
  bool bounded = false;               // Matrix_mode: the bounded mode ran (no dense matrix)
  std::string mode_reason;            // which mode and why, one line
  std::vector<std::string> notes;     // outputs asked for but not possible in this mode
  std::vector<std::string> warnings;  // Descriptor_cache problems that only cost time
  std::string cache;                  // Descriptor_cache: hits and file, one line; empty = off
  std::vector<Match> matches;         // kept matches (bounded mode, or Matches_name asked)
  RunTimings timings;
};

}  // namespace openable
