// The whole SNAPS chain as one library call (openable_snaps and openable.snaps.run are thin
// layers over it): a drifting trajectory (read from a file, or computed from the images by the
// odometry front-end), loop pairs (SNAPS's own search on thumbnails, a pairs file, a saved
// OpenABLE matrix, or an OpenABLE run on the same images), the corrections (the paper's
// discounted update, Eq. 6, and/or a pose graph), and, with a ground truth, the absolute
// trajectory error of each. docs/snaps.md explains every step.
#pragma once

#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/snaps/loop_search.h"
#include "OpenABLE/snaps/loops.h"
#include "OpenABLE/snaps/pose_graph.h"
#include "OpenABLE/snaps/trajectory.h"
#include "config/config.h"

namespace openable::snaps {

// What the odometry front-end did (Snaps_odometry mono or stereo).
struct OdometryReport {
  std::string kind;             // "mono", "stereo"
  std::string scale;            // where the scale came from, one line
  std::vector<double> seconds;  // per frame
  int failed = 0;               // steps that kept the previous motion
  std::string first_failure;    // "frame N: why"
};

// The absolute trajectory error of one trajectory, unaligned and after a rigid alignment.
struct ChainErrors {
  std::string name;  // "input", "discounted", "pose_graph"
  TrajectoryError raw, aligned;
};

// Everything one run of the chain produced.
struct ChainResult {
  Trajectory input;             // the trajectory corrected (read, or computed by odometry)
  std::string trajectory_name;  // its file, or "mono odometry" / "stereo odometry"
  bool computed = false;        // the trajectory came from the odometry front-end
  OdometryReport odometry;
  bool evaluated = false;  // a ground truth was given
  Trajectory truth;
  std::vector<int> association;  // index in `truth` of each pose of `input`
  std::vector<LoopPair> loops;   // indices of `input`
  bool verified_loops = false;   // Snaps_loops openable with Verification 1: verified answers
  // Matrix rows mapped to poses by time (frames with times and a TUM trajectory), not frame id.
  bool loops_by_time = false;
  // Snaps_loops pairs, matrix, openable: the pairs of the file or the matrix's matches below the
  // threshold, on poses, associated to the nearest pose within Snaps_keyframe_tolerance, dropped
  // or (pairs file) outside the trajectory; `loops` is what remains after MiddleOfRuns (pairs)
  // or one loop per query pose (matrix).
  PairCounts pairs;
  double loop_seconds = 0;      // finding or reading the loops
  ImageSearchResult searched;   // Snaps_loops search: the online search and its latencies
  bool discounted_ran = false;  // Snaps_corrector discounted or both
  Trajectory discounted;
  std::vector<LoopPair> closed;  // the loops the discounted update closed
  double discounted_seconds = 0;
  bool graph_ran = false;  // Snaps_corrector pose-graph or both
  Trajectory graph;
  PoseGraphReport graph_report;
  std::vector<ChainErrors> errors;  // with a ground truth: input, then each correction
};

// Runs the chain of `config` (checked first: CheckSnapsConfig). Long stages report to
// `progress`; `say` receives a few lines of what is being done (may be empty). Throws
// InputError naming the key, file or value on any problem with the configuration or the data.
ChainResult RunChain(const Config& config, ProgressReporter& progress,
                     const std::function<void(const std::string&)>& say = {});

// The report openable_snaps prints: trajectory, odometry, loops, corrections, errors and
// latencies, a few lines; text that is not valid UTF-8 shown by ToValidUtf8.
std::string FormatChainReport(const Config& config, const ChainResult& result);

// The figures as JSON (<Snaps_output_name>.json), 6 significant digits, null when not finite;
// EncodeChainJson is its text (json::Dump).
nlohmann::ordered_json ChainJson(const Config& config, const ChainResult& result);
std::string EncodeChainJson(const Config& config, const ChainResult& result);

// Writes the outputs of Snaps_output_name = P, all or nothing: P_discounted.txt and/or
// P_pose_graph.txt (the input's format), P_odometry.txt (a computed trajectory), P_loops.csv,
// P.json, P.png (and P_discounted.png when both corrections ran). Returns the paths written;
// none when Snaps_output_name is empty. Throws InputError naming the key and path on failure.
std::vector<std::string> WriteChainOutputs(const Config& config, const ChainResult& result);

}  // namespace openable::snaps
