#include "config/run_options.h"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/option_checks.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

// Throws InputError "<key>: empty; expected a path (<why>)" when `value` is empty.
void NeedPath(const std::string& value, const std::string& key, const std::string& why) {
  if (value.empty()) throw InputError(key + ": empty; expected a path (" + why + ")");
}

}  // namespace

void InputOptions::Check() const {
  CheckIntAtLeast("Initial_image", initial_image, 0);
  CheckIntAtLeast("Final_image", final_image, -1);
  const int mode = static_cast<int>(frame_mode);
  if (camera_type == CameraType::kStereo) {
    if (frame_mode != FrameMode::kImageFolders && frame_mode != FrameMode::kBag)
      throw InputError("Frame_mode: " + std::to_string(mode) +
                       " with Camera_type 1 (stereo); expected 0 (the image folders "
                       "Images_path_left and Images_path_right) or 3 (the topics Bag_topic and "
                       "Bag_topic_right of a bag), not videos");
    if (!images_path_2.empty())
      throw InputError("Images_path_2: " + Quoted(images_path_2) +
                       " with Camera_type 1 (stereo); expected empty: a second stereo "
                       "traversal is not supported");
    if (frame_mode == FrameMode::kBag) {
      if (!bag_topic_2.empty())
        throw InputError("Bag_topic_2: " + Quoted(bag_topic_2) +
                         " with Camera_type 1 (stereo); expected empty: a second stereo "
                         "traversal is not supported");
      NeedPath(bag_topic_right, "Bag_topic_right",
               "Camera_type 1 with Frame_mode 3 reads the right camera's image topic");
    } else {
      NeedPath(images_path_left, "Images_path_left", "Camera_type 1 reads a left image folder");
      NeedPath(images_path_right, "Images_path_right", "Camera_type 1 reads a right image folder");
    }
    NeedPath(calibration_path, "Calibration_path", "Camera_type 1 needs a stereo calibration");
  }
  switch (frame_mode) {
    case FrameMode::kImageFolders:
      if (camera_type != CameraType::kStereo)
        NeedPath(images_path, "Images_path", "Frame_mode 0 reads an image folder");
      break;
    case FrameMode::kVideo:
      NeedPath(video_path_1, "Video_path_1", "Frame_mode 1 reads a video");
      break;
    case FrameMode::kTwoVideos:
      NeedPath(video_path_1, "Video_path_1", "Frame_mode 2 reads two videos");
      NeedPath(video_path_2, "Video_path_2", "Frame_mode 2 reads two videos");
      break;
    case FrameMode::kBag:
      NeedPath(bag_path, "Bag_path", "Frame_mode 3 reads a ROS 1 bag");
      if (bag_topic.empty())
        throw InputError("Bag_topic: empty; expected the image topic to read from bag " +
                         Quoted(bag_path) + " (e.g. /cam0/image_raw)");
      if (!bag_path_2.empty() && bag_topic_2.empty())
        throw InputError("Bag_topic_2: empty, but Bag_path_2 is " + Quoted(bag_path_2) +
                         "; expected the image topic of the second traversal");
      break;
  }
  if (final_image != -1 && final_image <= initial_image)
    throw InputError("Final_image: " + std::to_string(final_image) +
                     " is not after Initial_image " + std::to_string(initial_image) +
                     "; expected -1 (to the end) or a position > Initial_image");
}

std::string OutputOptions::ThresholdPngPath(bool thresholded) const {
  if (!thresholded) return "";
  if (!png_threshold_name.empty()) return png_threshold_name;
  if (png_name.empty()) return "";
  const std::filesystem::path p(png_name);
  return (p.parent_path() / (p.stem().string() + "_thresholded" + p.extension().string())).string();
}

void OutputOptions::Check() const {
  CheckIntRange("Matrix_color", matrix_color, 0, 11);
  // The matrix images are written as PNG (lossless: a JPEG would blur the distances), so a
  // path that names another format would hold PNG bytes under the wrong name.
  for (const auto& [key, path] : {std::pair<const char*, const std::string&>{"Png_name", png_name},
                                  {"Png_threshold_name", png_threshold_name}}) {
    if (path.empty()) continue;
    const auto dot = path.find_last_of("./");
    const std::string ext =
        dot == std::string::npos || path[dot] != '.' ? "" : Lower(path.substr(dot));
    if (ext != ".png")
      throw InputError(std::string(key) + ": " + Quoted(path) +
                       " does not end in .png; expected a .png path (the matrix image is "
                       "written as PNG, lossless)");
  }
}

void ScaleOptions::Check() const {
  CheckNumberAtLeast("Memory_limit", memory_limit, 0);
  keep.Check();
  // The ranges are ApproximateOptions' (the option table gives the keys the same).
  const auto check = [](const char* key, int value, ApproximateRange range) {
    CheckIntRange(key, value, range.min, range.max);
  };
  check("Approximate_checks", approximate.checks, ApproximateOptions::kChecksRange);
  check("Approximate_ef_search", approximate.ef_search, ApproximateOptions::kEfSearchRange);
  check("Approximate_nprobe", approximate.nprobe, ApproximateOptions::kNprobeRange);
  ParseApproximateEngine(approximate.engine, "Approximate_engine");
  // The fields no key sets (a program may): named as the struct's field.
  try {
    approximate.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("ScaleOptions.approximate: ") + e.what());
  }
  if (approximate_search) CheckEngineAvailable(approximate.engine, "Approximate_engine");
  if (approximate_search && matrix_mode == MatrixMode::kDense)
    throw InputError(
        "Approximate_search: 1 needs Matrix_mode 2 (bounded) or 0 (auto); "
        "Matrix_mode is 1 (dense), which compares every pair");
  if (matrix_mode == MatrixMode::kBounded && matches_name.empty())
    throw InputError(
        "Matches_name: empty, but Matrix_mode 2 (bounded) keeps only matches; "
        "expected a .npy or .csv path");
  if (!matches_name.empty()) {
    const auto dot = matches_name.find_last_of('.');
    const std::string ext = dot == std::string::npos ? "" : matches_name.substr(dot);
    if (ext != ".npy" && ext != ".csv")
      throw InputError("Matches_name: " + Quoted(matches_name) + " has extension " +
                       (ext.empty() ? std::string("(none)") : ext) + "; expected .npy or .csv");
  }
}

void AutoOptions::Check() const {
  if (!(min_consistency >= 0.0 && min_consistency <= 1.0))
    throw InputError("Auto_min_consistency: " + FormatNumber(min_consistency) +
                     " is not valid; expected a share of the queries in [0, 1]");
}

void EvaluationConfig::Check() const {
  truth.Check();
  protocol.Check();
  CheckIntAtLeast("Ground_truth_min_gap", min_frame_gap, -1);
  CheckIntRange("Report_examples", report_examples, 0, 100);
}

}  // namespace openable
