// Ground truth for evaluating a distance matrix: which (query, reference) pairs of the evaluated
// block are the same place. Read from a binary matrix, a list of pairs, frame-aligned
// traversals, or poses / positions per frame (evaluation.md, "Ground truth inputs").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "OpenABLE/base/enum_names.h"

#include "OpenABLE/evaluation/layout.h"

namespace openable {

// True matches over the evaluated block of an EvaluationLayout.
struct GroundTruth {
  // matches[q]: sorted, distinct column indices (0 .. references-1) of the block that are the
  // same place as query row q. Size = layout.queries.
  std::vector<std::vector<int>> matches;
  int references = 0;
  // Pairs dropped while loading: pairs on the diagonal (q, q) of a loop-closure layout, and,
  // when a frame range was selected (first_frame > 0 or range_selected), pairs outside it
  // (without a range, a pair past the last frame is an error: a wrong file). (Pairs
  // inside the exclusion window are kept here; the evaluation leaves them out and says so.)
  std::int64_t dropped = 0;

  std::int64_t PairCount() const {
    std::int64_t n = 0;
    for (const auto& m : matches) n += static_cast<std::int64_t>(m.size());
    return n;
  }
  int PositiveQueries() const {  // queries with at least one match
    int n = 0;
    for (const auto& m : matches) n += m.empty() ? 0 : 1;
    return n;
  }
};

enum class GroundTruthType {
  kNone,       // no evaluation
  kMatrix,     // binary matrix: text 0/1, PNG/BMP/any image OpenCV reads (non-zero = match), .npy
  kPairs,      // list of pairs "row,col" (or "row col"), '#' comments, extra columns ignored
  kAligned,    // frame-aligned traversals: query i is reference i
  kKitti,      // KITTI poses: 12 numbers per line, a 3x4 camera-to-world matrix [R | t]
  kTum,        // TUM trajectory: "timestamp tx ty tz qx qy qz qw" per line, '#' comments
  kPositions,  // CSV/whitespace "x,y[,z]" per line (no orientation), '#' comments
};
OPENABLE_ENUM_NAMES(GroundTruthType, "none", "matrix", "pairs", "aligned", "kitti", "tum",
                    "positions")

// Parses "matrix", "pairs", "aligned", "kitti", "tum", "positions" (and "" = kNone). Throws
// InputError naming Ground_truth_type otherwise.
GroundTruthType ParseGroundTruthType(const std::string& name);
std::string GroundTruthTypeName(GroundTruthType type);

struct GroundTruthOptions {
  GroundTruthType type = GroundTruthType::kNone;
  std::string path;        // the file (matrix, pairs; poses of the reference or only sequence)
  std::string path_2;      // poses of the query traversal (pose types, two traversals)
  int base = -1;           // pairs: 0- or 1-based indices; -1 = from a header comment that says
                           // "0-based" or "1-based", else 0
  int first_frame = 0;     // frame number of row 0 (Initial_image): pair indices and pose lines
                           // count from the start of the source, rows from first_frame
  bool range_selected = false;  // the run processes part of its source (Initial_image > 0 or
                                // Final_image != -1): pairs outside it are dropped, not errors
  double radius = 5.0;     // poses: a pair is a loop when the positions are closer than this
                           // (same unit as the file, metres for KITTI), > 0
  double heading_limit = -1.0;  // poses: and when the viewing directions differ by less than
                                // this many degrees (-1 = no limit); needs orientations
  int min_frame_gap = 100;  // poses, loop closure: only pairs with q - j >= min_frame_gap
  std::string axes = "xyz";  // poses: axes of the distance and heading: "xyz" (3D), "xz" (the
                             // ground plane of KITTI's camera frame), "xy"
  // tum with frames that carry times (ROS bags): the time of each frame of the reference (or
  // only) traversal and of the query traversal, in seconds; a frame takes the pose with the
  // nearest timestamp, within time_tolerance seconds. Empty: pose line i is frame i.
  std::vector<double> frame_times, frame_times_2;
  double time_tolerance = 0.02;

  // Throws InputError naming the Config.txt key (Ground_truth_radius, ...) of a bad value.
  void Check() const;
};

// Loads the ground truth of `options` over `layout` (a block of a full_rows x full_cols
// matrix). Loop closure: a pair (a, b) is stored as (max, min), the later frame is the query;
// pairs are symmetric. Query-reference: a pair is (query row, reference column) in the block's
// own indices (0 = first frame of that traversal). A ground-truth matrix may have the block's
// size or the full matrix's (then the same block is taken from it). Throws InputError with one
// line naming the file (and line) or key: unreadable or malformed file, a matrix whose size is
// neither the block's nor the full matrix's, pairs outside the range, pose files whose frame count
// does not cover the run, a heading limit without orientations, aligned ground truth on a
// loop-closure layout.
GroundTruth LoadGroundTruth(const GroundTruthOptions& options, const EvaluationLayout& layout,
                            int full_rows, int full_cols);

// One pose per frame: position, and viewing direction (the camera's optical axis, unit vector,
// the third column of R for KITTI and TUM) when the format has orientations.
struct FramePose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d forward = Eigen::Vector3d::Zero();
  bool has_forward = false;
};

// Reads a pose or position file of type kKitti, kTum or kPositions. Throws InputError naming
// the file and line of the first malformed line, or an empty file.
std::vector<FramePose> ReadPoses(const std::string& path, GroundTruthType type);

// Loop pairs from poses. Loop closure (`reference` empty): pairs (q, j) with
// q - j >= min_frame_gap. Two traversals: every (query q, reference r). A pair is kept when the
// distance over `axes` is < radius and, with heading_limit >= 0, the angle between the forward
// vectors projected on `axes` is < heading_limit degrees. Returns matches per query.
std::vector<std::vector<int>> PairsFromPoses(const std::vector<FramePose>& queries,
                                             const std::vector<FramePose>& reference,
                                             const GroundTruthOptions& options);

}  // namespace openable
