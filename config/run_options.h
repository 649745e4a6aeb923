// The option structs of a run of Test_OpenABLE that belong to no single module: its inputs,
// its output files, its scale (dense or bounded) and its evaluation. The modules' own option
// structs (descriptors, matching, preprocessing, SNAPS, odometry) live with their modules;
// config.h gathers all of them into Config.
#pragma once

#include <string>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/evaluation/ground_truth.h"
#include "OpenABLE/evaluation/metrics.h"
#include "matching/bounded.h"
#include "matching/search/approximate.h"

namespace openable {

// Frame_mode: image folders (Images_path, optionally Images_path_2), one video, two videos.
enum class FrameMode { kImageFolders = 0, kVideo = 1, kTwoVideos = 2, kBag = 3 };
OPENABLE_ENUM_NAMES(FrameMode, "image folders", "video", "two videos", "ROS bag")

// Camera_type: monocular (ABLE-M), stereo (ABLE-S), panoramic (ABLE-P).
enum class CameraType { kMonocular = 0, kStereo = 1, kPanoramic = 2 };
OPENABLE_ENUM_NAMES(CameraType, "monocular", "stereo", "panoramic")

// Matrix_mode: dense when it fits Memory_limit (auto), always dense, or bounded.
enum class MatrixMode { kAuto = 0, kDense = 1, kBounded = 2 };
OPENABLE_ENUM_NAMES(MatrixMode, "auto", "dense", "bounded")

// Where the frames of a run come from (the Datasets keys and Camera_type).
struct InputOptions {
  FrameMode frame_mode = FrameMode::kImageFolders;
  std::string images_path;        // folder of the (first) traversal
  std::string images_path_2;      // folder of a second traversal, matched against the first
  std::string images_path_left;   // stereo: left folder
  std::string images_path_right;  // stereo: right folder
  std::string calibration_path;   // stereo: calibration of the pair
  std::string images_format;      // extension of the images taken; empty: every image type
  std::string video_path_1;       // video of Frame_mode 1 and 2
  std::string video_path_2;       // second video of Frame_mode 2
  std::string bag_path;           // ROS 1 bag of Frame_mode 3
  std::string bag_topic;          // its image topic (the left camera's with Camera_type 1)
  std::string bag_topic_right;    // stereo: the right camera's image topic
  std::string bag_path_2;         // bag of a second traversal; empty: Bag_path
  std::string bag_topic_2;        // image topic of a second traversal; empty: one traversal
  int initial_image = 0;          // first position (natural order) processed, >= 0
  int final_image = -1;           // one past the last position; -1: to the end
  bool skip_unreadable = false;   // skip unreadable frames with a warning instead of stopping
  CameraType camera_type = CameraType::kMonocular;
  // Rows computed elsewhere (a .npy of one row per frame), in place of describing the frames
  // of the first and of the second traversal (OpenABLE/run/given_rows.h).
  std::string descriptors_path;
  std::string descriptors_path_2;

  // Throws InputError naming the key: a range that selects nothing, the inputs the frame mode
  // and camera read not given, a stereo camera with videos or a second traversal.
  void Check() const;
};

// The files of the matrix (the Representation keys).
struct OutputOptions {
  std::string txt_name;            // M' (or M'' with a threshold) as text; empty: not written
  std::string npy_name;            // M' as float32 .npy; empty: not written
  std::string png_name;            // M' as a colour image; empty: not written
  std::string png_threshold_name;  // M'' as an image; empty: Png_name + "_thresholded"
  std::string loops_name;          // verification: every candidate checked, CSV; empty: none
  std::string timestamps_name;     // the time of every frame (ROS bags), text; empty: none
  int matrix_color = 0;            // colour map, 0..11 (docs/output_formats.md)
  bool show_images = false;        // show each frame while it is described

  // The thresholded image's path: Png_threshold_name, or Png_name with "_thresholded" before
  // its extension; empty when `thresholded` is false or no PNG is asked for.
  std::string ThresholdPngPath(bool thresholded) const;
  // Throws InputError naming Matrix_color out of range.
  void Check() const;
};

// Dense or bounded matrices, and what the bounded mode keeps (the Scale keys).
struct ScaleOptions {
  MatrixMode matrix_mode = MatrixMode::kAuto;
  double memory_limit = 0.0;        // GiB the dense matrices may take, >= 0; 0: 3/4 of the RAM
  KeepRules keep;                   // Best_matches and Band_width (its exclusion: Exclusion)
  std::string matches_name;         // kept matches, .npy or .csv
  bool approximate_search = false;  // approximate candidates instead of every pair (bounded)
  // The engine and search budget of those candidates (matching/search/approximate.h; the keys
  // Approximate_engine, Approximate_checks, Approximate_ef_search and Approximate_nprobe are
  // bound onto its fields). The run sets its k (from Best_matches) and threads.
  ApproximateOptions approximate;
  std::string descriptor_cache;  // folder of the descriptor cache; empty: off

  // Throws InputError naming the key: a value out of range, approximate search with the dense
  // mode, the bounded mode without Matches_name, a matches file that is not .npy or .csv.
  void Check() const;
};

// The auto mode (the Auto keys, config/presets/auto.txt): the description and matching
// settings of a run of two traversals chosen from the data, without ground truth
// (OpenABLE/tuning/auto.h; docs/evaluation.md, "Without ground truth").
struct AutoOptions {
  bool enabled = false;  // Auto
  // Auto_candidates: groups separated by '|', each a product of axes "Key=v1,v2" separated by
  // spaces (values as openable_sweep's --vary takes them).
  std::string candidates = kDefaultCandidates;
  // Auto_min_consistency: the chosen setting is trusted when at least this share of the best
  // matches are confirmed by an independent query's (consistency), in [0, 1].
  double min_consistency = 0.5;

  // The candidates measured across the shared datasets (docs/benchmarks.md, "Settings chosen
  // from the data"; DenseVLAD's group: "A descriptor for viewpoint and light together").
  static constexpr const char* kDefaultCandidates =
      "Image_descriptor=HOG,SIFT,LDB,HOG+LDB Image_sequences=10,20,40 | "
      "Image_descriptor=SAD Contrast_enhancement=1 Image_sequences=10,20,40 | "
      "Image_descriptor=DenseVLAD Image_sequences=10,20,40";

  // Throws InputError naming the key of a bad value (the candidates' own checks are the auto
  // mode's, OpenABLE/tuning/auto.h).
  void Check() const;
};

// The evaluation of a run (the Evaluation keys).
struct EvaluationConfig {
  GroundTruthOptions truth;    // the ground truth (its frame gap, first frame and range: below)
  int min_frame_gap = -1;      // Ground_truth_min_gap: poses, one sequence; -1: Exclusion
  EvaluationOptions protocol;  // Tolerance, Exclusion, Vicinity
  std::string name;            // output prefix (Evaluation_name); empty: the table only
  std::string label;           // legend label (Evaluation_label); empty: descriptor and L
  // Self-contained HTML report (Report_name): of the evaluation with Ground_truth_type, else
  // of the run's answers; empty: none.
  std::string report_name;
  // Frames shown per kind in the report (Report_examples): worst cases with ground truth,
  // most and least confident accepted matches without.
  int report_examples = 6;

  bool Requested() const { return truth.type != GroundTruthType::kNone; }
  // Throws InputError naming the key of a bad value (GroundTruthOptions::Check,
  // EvaluationOptions::Check, Ground_truth_min_gap below -1).
  void Check() const;
};

}  // namespace openable
