// One run of OpenABLE: frames -> descriptors -> distances -> sequences -> normalised matrix
// (-> thresholded matrix). Its files are written by OpenABLE/outputs/run_outputs.h.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/base/progress.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/run/plan.h"
#include "OpenABLE/run/result.h"
#include "config/config.h"

namespace openable {

// The single-frame distance matrix of one descriptor over a run's frames, before fusion,
// contrast enhancement and sequences, with what the run reports of its description.
struct SingleFrame {
  RunDescriptor descriptor;
  cv::Mat1f distances;  // N x N, every frame against every frame
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

// Computes the matrices of a planned run (PlanRun, plan.h): reads the plan's frames and changes
// nothing in the plan. Throws InputError (one line naming the key, file or value) on a problem
// with the input data the check phase could not see (an unreadable frame, a changed file).
// Progress goes to `progress`. With `store`, a dense run takes its single-frame matrices from
// it when they are there, and keeps those it computes.
RunResult ComputeRun(const RunPlan& plan, ProgressReporter& progress,
                     SingleFrameStore* store = nullptr);

// PlanRun then ComputeRun: the run of `config`, checked then computed.
RunResult ComputeRun(const Config& config, ProgressReporter& progress,
                     SingleFrameStore* store = nullptr);

// The first part of a dense ComputeRun alone: the single-frame matrix of each descriptor of
// `config`, kept in `store` (described and compared unless the store holds it already). The
// result carries the traversals, timings, notes and warnings; no matrix. For runs that build
// several matrices from the same descriptions (the auto mode). Throws InputError as ComputeRun
// does, and for a run that would be bounded (PlanScope::kSingleFrames).
RunResult ComputeSingleFrames(const Config& config, ProgressReporter& progress,
                              SingleFrameStore& store);

// ComputeSingleFrames for several dense runs over the same frames (the auto mode's candidates,
// a sweep's combinations): the descriptors of the runs that share every other description
// setting (SingleFrameKey without the descriptor) are described in one run, as if fused, so
// that each frame is read and decoded once for all of them (DescribeSequences); their
// single-frame matrices are kept per descriptor, as each run would keep them. Returns the
// result of each such group, in the order of their first run.
std::vector<RunResult> ComputeSingleFramesTogether(const std::vector<Config>& configs,
                                                   ProgressReporter& progress,
                                                   SingleFrameStore& store);

// The single-frame matrix of a dense run of `config` from the matrices `store` holds (its
// descriptors' matrices fused with Fusion_weights, then contrast-enhanced): the matrix
// ComputeRun sums sequences over, on one process. `starts` are the traversals' first rows.
// Throws std::logic_error when the store lacks a descriptor's matrix.
cv::Mat1f SingleFrameMatrix(const Config& config, const SingleFrameStore& store,
                            const std::vector<int>& starts);

// The check phase alone: PlanRun, the plan discarded.
void CheckRun(const Config& config);

// The block a run's matrix is evaluated on: the query-reference block of two traversals, or
// the whole matrix of one sequence as loop closure.
EvaluationLayout LayoutOf(const RunResult& result);

}  // namespace openable
