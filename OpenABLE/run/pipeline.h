// One run of OpenABLE: frames -> descriptors -> distances -> sequences -> normalised matrix
// (-> thresholded matrix) -> output files. Test_OpenABLE is a thin layer over these two calls.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/io/frame_source.h"
#include "matching/bounded.h"
#include "matching/distances.h"
#include "OpenABLE/run/progress.h"
#include "config/config.h"

namespace openable {

struct Evaluation;       // OpenABLE/run/evaluate.h
struct RunVerification;  // OpenABLE/run/verify.h
struct AutoChoice;       // OpenABLE/run/auto.h

// One traversal of the run (a folder or a video) and the rows it holds in the matrix.
struct Traversal {
  std::string key;                  // config key it came from ("Images_path", ...)
  std::string path;                 // its folder or video
  int first_row = 0;                // its first row (and column) in the matrix
  int frames = 0;                   // rows it holds
  std::vector<std::string> names;   // frame name of each row (file path or video#index)
  std::vector<double> times;        // seconds of each row (ROS bags); empty: no times
  std::vector<std::string> skipped; // frames skipped as unreadable (Skip_unreadable 1)
  cv::Size frame_size;
};

struct RunTimings {
  double describe_seconds = 0;   // reading and describing every frame (wall time)
  double match_seconds = 0;      // pairwise distances (wall time)
  double sequence_seconds = 0;   // sequence sums, normalisation and threshold
  double evaluate_seconds = 0;   // evaluation against ground truth (when asked for)
  double export_seconds = 0;     // encoding and writing the outputs
  double total_seconds = 0;
  int frames = 0;                // frames described
  std::int64_t pairs = 0;        // distinct pairs of frames compared
};

// One descriptor of a run (several when Image_descriptor fuses them).
struct RunDescriptor {
  std::string name;       // registry name
  int row_width = 0;      // elements per frame descriptor
  Metric metric = Metric::kHamming;
};

struct RunResult {
  std::vector<Traversal> traversals;  // in matrix order
  std::string descriptor;             // registry name, or the fused names joined by "+"
  std::vector<RunDescriptor> descriptors;  // each descriptor (one unless fused)
  std::vector<double> fusion_weights;      // fused: the weight of each descriptor's matrix
  std::string camera;                 // camera and preprocessing, one line ("monocular, grey")
  cv::Mat1f normalized;               // M' of Eq. 5 (N x N over the concatenated traversals)
  float max_distance = 0;             // max(M), the divisor of Eq. 5
  // Cells of `normalized` that hold +inf: sequences skipped at a traversal's start
  // (Sequence_partial skip); never a best match, exported as documented in WriteOutputs.
  std::int64_t empty_cells = 0;
  cv::Mat1b thresholded;              // M'' of Eq. 9; empty when Threshold is -1
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

// The single-frame distance matrix of one descriptor over a run's frames, before fusion,
// contrast enhancement and sequences, with what the run reports of its description.
struct SingleFrame {
  RunDescriptor descriptor;
  cv::Mat1f distances;                // N x N, every frame against every frame
  std::vector<Traversal> traversals;
  std::string camera, cache;
  std::vector<std::string> warnings, notes;
  double describe_seconds = 0, match_seconds = 0;
  int frames = 0;
  std::int64_t pairs = 0;
};

// Single-frame matrices kept between dense runs of the same frames (openable_sweep): a run
// whose description settings (every key but those of matching, sequences, scores, outputs and
// evaluation) and descriptor match a kept matrix takes it instead of describing and comparing
// the frames again. Not thread-safe: one run at a time.
class SingleFrameStore {
 public:
  const SingleFrame* Find(const std::string& key) const;
  const SingleFrame& Keep(const std::string& key, SingleFrame frame);
  int Size() const { return static_cast<int>(kept_.size()); }

 private:
  std::vector<std::pair<std::string, std::unique_ptr<SingleFrame>>> kept_;
};

// The key of descriptor `name`'s single-frame matrix for the run of `config`.
std::string SingleFrameKey(const Config& config, const std::string& name);

// Computes the matrices of a run. Throws InputError (one line naming the key, file or value)
// on any problem with the configuration or the input data. Progress goes to `progress`.
// With `store`, a dense run takes its single-frame matrices from it when they are there, and
// keeps those it computes.
RunResult ComputeRun(const Config& config, ProgressReporter& progress,
                     SingleFrameStore* store = nullptr);

// The first part of a dense ComputeRun alone: the single-frame matrix of each descriptor of
// `config`, kept in `store` (described and compared unless the store holds it already). The
// result carries the traversals, timings, notes and warnings; no matrix. For runs that build
// several matrices from the same descriptions (the auto mode). Throws InputError as ComputeRun
// does; std::logic_error for a bounded configuration.
RunResult ComputeSingleFrames(const Config& config, ProgressReporter& progress,
                              SingleFrameStore& store);

// The single-frame matrix of a dense run of `config` from the matrices `store` holds (its
// descriptors' matrices fused with Fusion_weights, then contrast-enhanced): the matrix
// ComputeRun sums sequences over, on one process. `starts` are the traversals' first rows.
// Throws std::logic_error when the store lacks a descriptor's matrix.
cv::Mat1f SingleFrameMatrix(const Config& config, const SingleFrameStore& store,
                            const std::vector<int>& starts);

// The checks of ComputeRun that come before its first frame is described: the
// configuration, the descriptors and their fusion, the sources (folders, videos, calibration
// are opened, not read), the ratio window, the mode. Throws InputError as ComputeRun does.
void CheckRun(const Config& config);

// The block a run's matrix is evaluated on: the query-reference block of two traversals, or
// the whole matrix of one sequence as loop closure.
EvaluationLayout LayoutOf(const RunResult& result);

// Writes the outputs the configuration asks for (Txt_name, Npy_name, Png_name,
// Png_threshold_name, Loops_name when `verification` is given, and the files of
// Evaluation_name and Report_name when `evaluation` is given; the report lists the auto
// mode's candidates when `automatic` is given)
// all-or-nothing. Cells without a value (+inf, Sequence_partial skip) are written as the
// largest finite value in Txt_name and the PNG images and as NaN in Npy_name. Returns the
// paths written. Adds the time spent to result.timings.export_seconds. Throws InputError
// naming the key and path on failure.
std::vector<std::string> WriteOutputs(const Config& config, RunResult& result,
                                      const Evaluation* evaluation = nullptr,
                                      const RunVerification* verification = nullptr,
                                      const AutoChoice* automatic = nullptr);

// Every file a run of `config` may write, as (key, path): the matrix files, the thresholded
// image, the matches, the loops (Verification) and, when Ground_truth_type and
// Evaluation_name are set, the evaluation's files (StageEvaluation). Run checks them with
// CheckDistinctOutputs before any work.
std::vector<std::pair<std::string, std::string>> PlannedOutputs(const Config& config);

// The thresholded image's path: Png_threshold_name, or Png_name with "_thresholded" before
// its extension; empty when no threshold or no PNG is asked for.
std::string ThresholdPngPath(const Config& config);

// The frames of a run as images to look at (the left image of stereo pairs, as stored), one
// source per traversal in the order of the matrix: the reference (or only) traversal, then the
// second. For the HTML report's worst cases. Throws InputError naming the key, as a run does.
std::vector<std::unique_ptr<FrameSource>> OpenFramesToShow(const InputOptions& input);

}  // namespace openable
