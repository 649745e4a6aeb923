// Where SNAPS's loops come from: (a) a finished OpenABLE run (its normalised matrix), (b) a CSV
// of frame pairs (ground truth or another detector), (c) SNAPS's own search on thumbnails of
// the images (Sec. III-B), corrected online as the paper does.
#pragma once

#include <string>
#include <vector>

#include "OpenABLE/snaps/loop_search.h"
#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

// Frame id -> trajectory index: exactly, or the nearest pose's frame id within `tolerance`
// frames (ties: the earlier pose). -1 when none.
int IndexOfFrame(const Trajectory& trajectory, long frame_id, long tolerance);

// What became of the frame pairs of a pairs file or a matrix when their frame ids were mapped to
// the poses of a trajectory that may hold keyframes only (IndexOfFrame with a tolerance). Each
// pair considered is counted in exactly one of on_poses, associated, dropped, outside.
struct PairCounts {
  int on_poses = 0;    // kept, both frames are poses
  int associated = 0;  // kept, one frame or both moved to the nearest pose within the tolerance
  // A frame with no pose within the tolerance, or no loop once mapped (a frame with itself, or
  // both frames on one pose).
  int dropped = 0;
  int outside = 0;  // LoopsFromCsv with `outside`: a frame outside the trajectory's frame ids
  // LoopsFromMatrix: kept pairs (counted in on_poses or associated) whose query pose already has
  // a pair; each query pose keeps its most similar pair, so loops = on_poses + associated -
  // merged.
  int merged = 0;
  int Total() const { return on_poses + associated + dropped + outside; }
};

struct MatrixLoopOptions {
  // A loop needs M'(q, j) < threshold (M' in [0, 1]; 0 = identical).
  double threshold = 0.1;
  // Only j <= q - exclusion (matrix rows, i.e. frames) are matches of q.
  int exclusion = 100;
  // Frame id of the matrix's row 0 (the run's Initial_image).
  long initial = 0;
  // Frames whose id is not a pose of the trajectory map to the nearest pose within this many
  // frames; 0 keeps only frames that are poses (keyframes).
  long tolerance = 0;
  // Frames that carry times (ROS bags: Timestamps_name, or the run of Snaps_loops openable):
  // the time of each matrix row. With a trajectory that has timestamps (TUM), row i maps to the
  // pose with the nearest timestamp within time_tolerance seconds instead of by frame id.
  std::vector<double> frame_times;
  double time_tolerance = 0.02;
};

// (a) Loops from an OpenABLE matrix of one sequence (ReadMatrixFile: .npy, .txt, image). For
// each row q, its best earlier match j (smallest M'(q, j) with j <= q - exclusion; the earliest
// on ties) with M'(q, j) < threshold gives LoopPair{index(q), index(j), 1 - M'(q, j)}, frames
// mapped to trajectory indices by frame id (row i is frame initial + i) through IndexOfFrame;
// pairs with a frame that maps to no pose, or whose indices are not query > reference, are
// dropped; when several rows map to one query index the most similar is kept. A matrix whose
// maximum exceeds 1 (an image, 0-255) is first divided by its maximum. Throws InputError
// naming the file when the matrix is not square. With `counts` given, the pairs (rows whose
// best match is below the threshold) are counted there (outside stays 0).
std::vector<LoopPair> LoopsFromMatrix(const std::string& path, const Trajectory& trajectory,
                                      const MatrixLoopOptions& options,
                                      PairCounts* counts = nullptr);
// The same on a matrix in memory (e.g. RunResult::normalized of an OpenABLE run of the same
// frames); std::invalid_argument when it is not square.
std::vector<LoopPair> LoopsFromMatrix(cv::Mat1f matrix, const Trajectory& trajectory,
                                      const MatrixLoopOptions& options,
                                      PairCounts* counts = nullptr);

// One best match of an OpenABLE run of one sequence: rows of its matrix (frame ids initial +
// row) and the normalised distance M'.
struct FrameMatch {
  int query = 0, reference = 0;
  float distance = 0;
};

// Loops from best matches chosen elsewhere (a run's verified answers): frames mapped to
// trajectory indices as LoopsFromMatrix maps them, with the same drops, merges and counts;
// similarity 1 - distance.
std::vector<LoopPair> LoopsFromMatches(const std::vector<FrameMatch>& matches,
                                       const Trajectory& trajectory, long initial, long tolerance,
                                       PairCounts* counts = nullptr);
// The same with rows mapped by time when `times` holds one time per row and the trajectory has
// timestamps (MatrixLoopOptions::frame_times); otherwise by frame id as above.
std::vector<LoopPair> LoopsFromMatches(const std::vector<FrameMatch>& matches,
                                       const Trajectory& trajectory,
                                       const MatrixLoopOptions& options,
                                       PairCounts* counts = nullptr);

// The pose of `trajectory` (which has timestamps) nearest in time to `t`, -1 when none is
// within `tolerance` seconds.
int IndexOfTime(const Trajectory& trajectory, double t, double tolerance);

// Frame times as Timestamps_name writes them ("<row> <seconds>" per line, '#' comments, rows
// 0, 1, ... in order). Throws InputError naming `key`, the file and the line.
std::vector<double> ReadFrameTimes(const std::string& path, const std::string& key);

// (b) Loops from a file of pairs, read by ReadPairsFile (OpenABLE/evaluation/pairs_file.h): the
// format and checks of the evaluation's ground-truth pairs (comma or blanks, '#' comments, a
// header line, 0-based unless a comment says "1-based"), the later frame id first or second.
// Frame ids map to trajectory indices by IndexOfFrame(tolerance); a pair of a frame with
// itself, or with a frame inside the trajectory's frame range that maps to no pose (not a
// keyframe), is dropped (counted in `dropped` when given); similarity 1. Throws InputError,
// one line naming file:line and the value, as ReadPairsFile does, or when a frame id is
// outside the trajectory's frame ids [first, last].
// With `outside` given, pairs with a frame outside the trajectory's frame ids are dropped and
// counted there instead (a ground-truth list of a whole sequence against a trajectory that
// stops a few frames early). With `counts` given, every pair of the file is counted there
// (its dropped and outside equal the two counts above).
std::vector<LoopPair> LoopsFromCsv(const std::string& path, const Trajectory& trajectory,
                                   long tolerance = 0, int* dropped = nullptr,
                                   int* outside = nullptr, PairCounts* counts = nullptr);

// The nearest place of each loop run: ground-truth lists pair a query with every earlier frame
// within some radius (up to 40 m in KITTI 00), so a query's references come in runs of
// consecutive frames whose middle is the nearest place and whose ends are not "the same place".
// The references of one query are split into runs (frame ids less than `run_gap` apart) and
// only the middle reference of each run is kept (the earlier of two middles). Output sorted by
// query then reference; similarity of the kept pair as given.
std::vector<LoopPair> MiddleOfRuns(std::vector<LoopPair> loops, const Trajectory& trajectory,
                                   long run_gap = 10);

// (c) SNAPS's search on the images of a folder: frame id f of the trajectory is image
// `f - initial` of ListImages(folder, extension); each pose in order is read (ReadImageFile,
// ToGray8), reduced to its thumbnail (options.thumbnail_scale) and fed to OnlineSnaps with the
// trajectory's pose as the odometry. Throws InputError when a frame id has no image.
struct ImageSearchResult {
  std::vector<LoopPair> loops;             // indices of the trajectory
  Trajectory corrected;                    // the trajectory as corrected online
  std::vector<StepRecord> steps;           // one per pose (search latency and what happened)
  std::vector<double> correction_seconds;  // one per loop
  std::vector<double> thumbnail_seconds;   // one per pose: read + grey + thumbnail
};
ImageSearchResult SearchLoopsInImages(const std::string& folder, const std::string& extension,
                                      long initial, const Trajectory& trajectory,
                                      const SearchOptions& options);

// The same on thumbnails already made (thumbnails[i] belongs to pose i).
ImageSearchResult SearchLoopsInThumbnails(const std::vector<cv::Mat>& thumbnails,
                                          const Trajectory& trajectory,
                                          const SearchOptions& options);

}  // namespace openable::snaps
