// One run of OpenABLE: frames -> descriptors -> distances -> sequences -> normalised matrix
// (-> thresholded matrix). Its files are written by OpenABLE/outputs/run_outputs.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/run/result.h"
#include "config/config.h"

namespace openable {

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

// The frames of a run as images to look at (the left image of stereo pairs, as stored), one
// source per traversal in the order of the matrix: the reference (or only) traversal, then the
// second. For the HTML report's worst cases. Throws InputError naming the key, as a run does.
std::vector<std::unique_ptr<FrameSource>> OpenFramesToShow(const InputOptions& input);

}  // namespace openable
