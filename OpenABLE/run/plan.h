// The check phase of a run: a RunPlan is a run's configuration checked, its descriptors
// created, its sources opened (their frames listed; no frame is decoded) and its mode decided.
// The compute phase (ComputeRun, pipeline.h) reads the plan and changes nothing in it, so that
// every check a run makes comes before its first frame is described, for Test_OpenABLE, the
// sweep, the auto mode, runs over processes and Python alike.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/run/result.h"
#include "config/config.h"
#include "descriptors/descriptor.h"
#include "descriptors/frame_describer.h"

namespace openable {

// Where a traversal's frames come from.
enum class SourceKind { kFolder, kVideo, kStereo, kBag, kStereoBag };

struct SourceSpec {
  std::string key, path;  // the configuration key that names the source, and its value
  SourceKind kind;
  std::string topic_key = {}, topic = {};  // bags: the topic and its key
};

// How much of a run a plan is checked for: the whole run, or its single-frame matrices alone
// (the auto mode, which compares dense matrices and refuses a run that would be bounded).
enum class PlanScope { kWholeRun, kSingleFrames };

struct RunPlan {
  Config config;                   // the run's configuration, checked
  std::vector<std::string> names;  // the descriptors of Image_descriptor (fused when several)
  std::vector<std::unique_ptr<Descriptor>> descriptors;     // one per name
  std::vector<std::unique_ptr<FrameDescriber>> describers;  // one per name
  std::vector<SourceSpec> specs;                            // one per traversal
  std::vector<std::unique_ptr<FrameSource>> sources;        // one per traversal, opened
  int strips = 1;              // sub-panoramas of a panoramic camera (1 otherwise)
  bool cross = false;          // sub-panoramas compared every one against every one
  std::int64_t row_bytes = 0;  // every descriptor's row of one frame
  // What the run's result starts with: descriptors (name, row width, metric), the descriptor
  // text, fusion weights, camera, notes, and the mode (bounded, mode_reason).
  RunResult head;

  bool Fused() const { return names.size() > 1; }
};

// Plans the run of `config`: checks the configuration (CheckConfig), creates the descriptors
// (and checks their fusion), refuses a descriptor row that cannot be held, opens every source
// (folders listed, videos and bags opened, stereo calibrations loaded; a bad second folder is
// reported before any work), checks the ratio window against the reference frames and the
// verification settings, and decides the mode (Matrix_mode, Memory_limit) from the frame
// counts. Throws InputError naming the key, file or value.
RunPlan PlanRun(const Config& config, PlanScope scope = PlanScope::kWholeRun);

// The sources of a run's traversals, in the order of the matrix.
std::vector<SourceSpec> SourcesOf(const InputOptions& input);

// The frames of a run as images to look at (the left image of stereo pairs, as stored), one
// source per traversal in the order of the matrix: the reference (or only) traversal, then the
// second. For the HTML report's worst cases. Throws InputError naming the key, as a run does.
std::vector<std::unique_ptr<FrameSource>> OpenFramesToShow(const InputOptions& input);

// OpenFramesToShow's sources cut to the rows of the run's matrix: frame i of source t is row i
// of traversals[t], so that frames the run skipped as unreadable (Skip_unreadable) do not shift
// the later ones. The rows are found by their names (Traversal::names). Throws std::logic_error
// when a traversal's names are not frames of its source, in its order.
std::vector<std::unique_ptr<FrameSource>> FramesOfRows(
    std::vector<std::unique_ptr<FrameSource>> sources, const std::vector<Traversal>& traversals);

}  // namespace openable
