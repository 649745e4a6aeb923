// Ground truth for evaluating a distance matrix: which (query, reference) pairs of the evaluated
// block are the same place. Read from a binary matrix, a list of pairs, frame-aligned
// traversals, or poses / positions per frame (evaluation.md, "Ground truth inputs").
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "OpenABLE/evaluation/layout.h"

namespace openable {

// True matches over the evaluated block of an EvaluationLayout.
struct GroundTruth {
  // matches[q]: sorted, distinct column indices (0 .. references-1) of the block that are the
  // same place as query row q. Size = layout.queries.
  std::vector<std::vector<int>> matches;
  // soft[q]: sorted columns of VPR_Tutorial's GTsoft that are not in GThard, the cells its
  // protocol counts neither right nor wrong; empty (no row at all) without a GTsoft.
  std::vector<std::vector<int>> soft;
  int references = 0;
  // Pairs dropped while loading: pairs on the diagonal (q, q) of a loop-closure layout, and,
  // when a frame range was selected (first_frame > 0 or range_selected), pairs outside it
  // (without a range, a pair past the last frame is an error: a wrong file). (Pairs
  // inside the exclusion window are kept here; the evaluation leaves them out and says so.)
  std::int64_t dropped = 0;
  // A first line of a pairs file read as a header and skipped, for the report: `line 1 of
  // "gt.txt": "a,b"`; "" when none.
  std::string skipped_header;

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

struct GroundTruthFormat;

// A value of Ground_truth_type: a format of the registry (GroundTruthFormats), or none (no
// evaluation). The built-in formats have names here for the code that sets one.
class GroundTruthType {
 public:
  constexpr GroundTruthType() = default;  // none
  // The format named `name` (a name of GroundTruthFormats(); Format() checks it).
  constexpr explicit GroundTruthType(std::string_view name) : name_(name) {}
  static const GroundTruthType kNone, kMatrix, kPairs, kAligned, kKitti, kTum, kPositions,
      kVprBench, kVprTutorial;

  // The format; throws std::logic_error for none or a name outside the registry.
  const GroundTruthFormat& Format() const;
  bool IsNone() const { return name_.empty(); }
  bool operator==(const GroundTruthType& other) const { return name_ == other.name_; }
  bool operator!=(const GroundTruthType& other) const { return name_ != other.name_; }

 private:
  std::string_view name_;  // of a format's static name
};

// Parses a format's name, case-insensitively ("" = none). Throws InputError naming
// Ground_truth_type and listing the formats otherwise.
GroundTruthType ParseGroundTruthType(const std::string& name);
// The format's name ("none" for none).
std::string GroundTruthTypeName(GroundTruthType type);

struct GroundTruthOptions {
  GroundTruthType type = GroundTruthType::kNone;
  std::string path;       // the file (matrix, pairs; poses of the reference or only sequence)
  std::string path_2;     // poses of the query traversal (pose types, two traversals)
  std::string soft_path;  // vpr_tutorial: GTsoft (.npy); "" = the GTsoft of a .npz, or none
  int base = -1;          // pairs: 0- or 1-based indices; -1 = from a header comment that says
                          // "0-based" or "1-based", else 0
  int first_frame = 0;    // frame number of row 0 (Initial_image): pair indices and pose lines
                          // count from the start of the source, rows from first_frame
  bool range_selected = false;  // the run processes part of its source (Initial_image > 0 or
                                // Final_image != -1): pairs outside it are dropped, not errors
  double radius = 5.0;          // poses: a pair is a loop when the positions are closer than this
                                // (same unit as the file, metres for KITTI), > 0
  double heading_limit = -1.0;  // poses: and when the viewing directions differ by less than
                                // this many degrees (-1 = no limit); needs orientations
  int min_frame_gap = 100;      // poses, loop closure: only pairs with q - j >= min_frame_gap
  std::string axes = "xyz";     // poses: axes of the distance and heading: "xyz" (3D), "xz" (the
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
  double time = std::numeric_limits<double>::quiet_NaN();  // formats with timestamps
  int line = 0;                                            // the line of the file
};

// Reads a file of a pose format (kitti, tum, positions: Format().read_poses). Throws
// InputError naming the file and line of the first malformed line, or an empty file;
// std::logic_error for a format without poses.
std::vector<FramePose> ReadPoses(const std::string& path, GroundTruthType type);

// A ground-truth format: a value of Ground_truth_type, for Test_OpenABLE, openable_evaluate,
// openable_sweep and Python's evaluate alike. A format either reads one pose per frame (the
// pairs then come from the poses: Ground_truth_radius, _axes, _min_gap, _heading) or loads the
// pairs itself. To add a format: its reader or loader and its entry in GroundTruthFormats()
// (ground_truth.cc), its section in docs/evaluation.md, and a test; every list users see (the
// key's help and reference, openable_evaluate's usage, the messages) is made from the registry.
struct GroundTruthFormat {
  const char* name;     // the value of Ground_truth_type
  const char* summary;  // what the file holds, in a few words (help and reference)
  const char* label;    // the file in messages: "KITTI poses", "ground truth pairs", ...
  bool needs_file;      // Ground_truth names a file
  // The format pairs a query traversal with a reference one (a square matrix of one sequence
  // is refused: Images_path_2, Frame_mode 2, --reference-frames, Python's layout).
  bool two_traversals;
  // A pose format: one pose per line, line i the frame i of the source (or, with
  // `timestamps`, the pose nearest in time to a frame that carries a time).
  std::vector<FramePose> (*read_poses)(const std::string& path, const char* label);
  bool orientations;  // the poses carry viewing directions (Ground_truth_heading applies)
  bool timestamps;    // the poses carry times (FramePose::time, increasing)
  // Any other format: fills gt->matches over the block of `layout` of a full_rows x full_cols
  // matrix (unsorted, maybe with duplicates) and counts gt->dropped.
  void (*load)(const GroundTruthOptions& options, const EvaluationLayout& layout, int full_rows,
               int full_cols, GroundTruth* gt);
};

// The aligned ground truth pairs query frame i with reference frame i: throws InputError
// (Ground_truth_type, both lengths) unless the traversals have as many frames.
void CheckAlignedLengths(int queries, int references);

// Every format, in the order users see them.
const std::vector<GroundTruthFormat>& GroundTruthFormats();
// The names of the formats, joined as a list for messages: "matrix, pairs, ... or positions"
// (`last_separator` before the last name).
std::string GroundTruthFormatList(const char* last_separator = " or ");

// Loop pairs from poses. Loop closure (`reference` empty): pairs (q, j) with
// q - j >= min_frame_gap. Two traversals: every (query q, reference r). A pair is kept when the
// distance over `axes` is < radius and, with heading_limit >= 0, the angle between the forward
// vectors projected on `axes` is < heading_limit degrees. Returns matches per query.
std::vector<std::vector<int>> PairsFromPoses(const std::vector<FramePose>& queries,
                                             const std::vector<FramePose>& reference,
                                             const GroundTruthOptions& options);

}  // namespace openable
