// libFuzzer target: the text readers of the ground truth. The first byte of the input chooses
// the reader (its bits 0-2, 7 read as 0) and the rest is written to a temporary file read by it:
//   0, 1, 2  ReadPairsFile (OpenABLE/evaluation/pairs_file.h) with base -1 (from a comment),
//            0 and 1, then LoadGroundTruth of type pairs over 40 frames, one sequence or (bit 3
//            of the first byte) 40 queries against 30 references, from frame (bits 4-5) 0-3;
//   3, 4, 5  ReadPoses (ground_truth.h) of KITTI poses, a TUM trajectory, positions, then
//            LoadGroundTruth of that type over (at most) the first 200 poses, one sequence;
//            for TUM, by time (Ground_truth_time_tolerance) when bit 3 is set;
//   6        ReadPoseFile (pose_file.h) of KITTI poses with frame numbers (SNAPS).
// The expected outcomes are the pairs or poses, or one InputError line naming the file; any
// other exception, a crash or a sanitizer report is a finding. Built with
// -DOPENABLE_BUILD_FUZZERS=ON (clang); see docs/robustness.md.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/layout.h"
#include "OpenABLE/evaluation/pairs_file.h"
#include "OpenABLE/evaluation/pose_file.h"
#include "tests/fuzz/fuzz_support.h"

namespace {

using openable::EvaluationLayout;
using openable::GroundTruthOptions;
using openable::GroundTruthType;
using openable::fuzz::Refuses;

void Load(const GroundTruthOptions& options, const EvaluationLayout& layout,
          const std::string& path) {
  Refuses(
      [&] {
        openable::LoadGroundTruth(options, layout, layout.row_offset + layout.queries,
                                  layout.col_offset + layout.references);
      },
      path);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int choice = (data[0] & 0x07) % 7;
  const bool variant = (data[0] & 0x08) != 0;
  const openable::fuzz::TempFile file(openable::fuzz::Bytes(data + 1, size - 1), ".txt");
  const std::string& path = file.Path();
  GroundTruthOptions options;
  options.path = path;
  options.min_frame_gap = 2;
  if (choice <= 2) {
    const int base = choice - 1;
    if (Refuses([&] { openable::ReadPairsFile(path, base, "ground truth pairs"); }, path)) return 0;
    options.type = GroundTruthType::kPairs;
    options.base = base;
    options.first_frame = (data[0] >> 4) & 3;
    Load(options,
         variant ? EvaluationLayout::TwoTraversals(30, 40) : EvaluationLayout::LoopClosure(40),
         path);
  } else if (choice <= 5) {
    const GroundTruthType types[] = {GroundTruthType::kKitti, GroundTruthType::kTum,
                                     GroundTruthType::kPositions};
    options.type = types[choice - 3];
    std::vector<openable::FramePose> poses;
    if (Refuses([&] { poses = openable::ReadPoses(path, options.type); }, path)) return 0;
    const int frames = static_cast<int>(std::min<std::size_t>(poses.size(), 200));
    if (variant && options.type == GroundTruthType::kTum)
      for (int i = 0; i < frames; ++i)
        options.frame_times.push_back(poses[i].time + 0.01 * (i % 3));
    Load(options, EvaluationLayout::LoopClosure(frames), path);
  } else {
    Refuses(
        [&] { openable::ReadPoseFile(path, openable::PoseFileFormat::kKittiWithId, "trajectory"); },
        path);
  }
  return 0;
}
