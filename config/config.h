// The configuration of a run: every Config.txt key bound once to a field of Config.
//
// The same table drives reading Config.txt, the `--set Key=Value` overrides, `--help` and the
// configuration reference in docs/configuration.md (conventions.md, item 4). Key names and
// meanings are those of the original OpenABLE (../shared/guide/reference.md), so an old
// configuration runs unchanged; keys marked "new" are additions documented in the reference.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace openable {

struct Config {
  // --- Datasets ---------------------------------------------------------------------------
  int frame_mode = 0;                 // 0 image folder(s), 1 one video, 2 two videos
  std::string images_path;            // folder of the (first) image sequence
  std::string images_path_2;          // new: folder of a second traversal, matched against the first
  std::string images_path_left;       // stereo left folder (Camera_type 1)
  std::string images_path_right;      // stereo right folder (Camera_type 1)
  std::string calibration_path;       // stereo calibration (Camera_type 1)
  std::string images_format;          // extension filter ("png"); empty = every image type
  std::string video_path_1;           // video for Frame_mode 1 and 2
  std::string video_path_2;           // second video for Frame_mode 2
  int initial_image = 0;              // first position (natural order) to process
  int final_image = -1;               // one past the last position; -1 = to the end
  int skip_unreadable = 0;            // new: 1 skips unreadable frames with a warning
  // --- Representation -----------------------------------------------------------------------
  std::string txt_name;               // text matrix; empty = not written
  std::string npy_name;               // new: float32 .npy of M'; empty = not written
  std::string png_name;               // colour image of M'; empty = not written
  std::string png_threshold_name;     // new: image of M''; empty = <Png_name>_thresholded.png
  int matrix_color = 0;               // colour map 0-11
  int show_images = 0;                // 1 shows frames while processing (needs a display)
  // --- Description and matching -------------------------------------------------------------
  int camera_type = 0;                // 0 monocular, 1 stereo, 2 panoramic
  int description_type = 0;           // 0 global, 1 grid
  int patch_size = 64;                // side of the square patch, pixels
  int grid_x = 2;                     // grid cells across (Description_type 1)
  int grid_y = 2;                     // grid cells down (Description_type 1)
  int panoramas = 4;                  // sub-panoramas (Camera_type 2)
  int illumination_invariance = 0;    // 1 applies Eq. 6
  double alpha = 0.47;                // alpha of Eq. 6
  double lambda_red = 0.0;            // new: peak spectral responses (nm) for Eq. 7; 0 = not
  double lambda_green = 0.0;          //   given
  double lambda_blue = 0.0;
  int panorama_matching = 1;          // new: 0 aligned, 1 cross-correlation, 2 circular
  std::string image_descriptor = "LDB";
  int image_sequences = 1;            // sequence length L; 1 = single images
  double threshold = -1.0;            // theta of Eq. 9 in [0, 1]; -1 disables
  int ldb_bits = 256;                 // new: LDB bits kept, 1-1386
  int threads = 0;                    // new: worker threads, 0 = all cores
  int sequence_direction = 0;         // new: 0 diagonals, 1 anti-diagonals, 2 min of both
  // --- Robustness (issue 8) ------------------------------------------------------------------
  int side_window = 0;                // new: 1 applies side-window multilayer fusion
  std::string side_window_radii = "1,2,3";  // new: radius of each layer, comma-separated
  double noise_gaussian = 0.0;        // new: variance of Gaussian noise on [0, 1]; 0 off
  double noise_salt_pepper = 0.0;     // new: fraction of salt-and-pepper pixels; 0 off
  double noise_overexposure = 0.0;    // new: exposure gain v (1 + g), saturating; 0 off
  int noise_seed = 0;                 // new: seed of the noise
  // --- Scale (new; docs/configuration.md) ----------------------------------------------------
  int matrix_mode = 0;                // 0 auto, 1 dense N x N, 2 bounded (tiles, kept matches)
  double memory_limit = 0.0;          // GiB the dense matrix may use; 0 = 3/4 of the RAM
  int best_matches = 10;              // k best matches kept per query
  int band_width = -1;                // also keep |i - j| <= this (frames); -1 none
  std::string matches_name;           // matches file (.npy or .csv); empty = not written
  int approximate_search = 0;         // 1: FLANN candidates instead of every pair (bounded)
  int approximate_checks = 512;       // FLANN checks per query
  std::string descriptor_cache;       // descriptor cache folder; empty = off
  // --- Evaluation (new) ----------------------------------------------------------------------
  std::string ground_truth_type;      // "", matrix, pairs, aligned, kitti, tum, positions
  std::string ground_truth;           // ground-truth file (poses of the reference, for poses)
  std::string ground_truth_2;         // poses of the query traversal (two traversals)
  int ground_truth_base = -1;         // pairs: 0 or 1-based; -1 = from the header, else 0
  double ground_truth_radius = 5.0;   // poses: loop when closer than this
  double ground_truth_heading = -1.0; // poses: and headings closer than this, degrees; -1 off
  int ground_truth_min_gap = -1;      // poses, one sequence: frames apart; -1 = Exclusion
  std::string ground_truth_axes = "xyz";  // poses: xyz, xz or xy
  int tolerance = 2;                  // frames: a match this close to a true one is right
  int exclusion = 100;                // one sequence: candidates at least this many frames back
  int vicinity = 7;                   // ABLE-P protocol: temporal vicinity, frames
  std::string evaluation_name;        // output prefix; empty = table only
  std::string evaluation_label;       // legend label; empty = "<descriptor> L=<L>"
  // --- SNAPS add-on (new; openable_snaps, docs/snaps.md) ---------------------------------------
  std::string snaps_trajectory;
  std::string snaps_trajectory_format = "kitti";
  int snaps_world_to_camera = 0;
  std::string snaps_ground_truth;
  std::string snaps_ground_truth_format = "kitti";
  double snaps_time_tolerance = 0.02;
  std::string snaps_loops = "search";     // search, pairs, matrix
  std::string snaps_loops_file;
  int snaps_keyframe_tolerance = 0;
  int snaps_middle_of_runs = 1;
  int snaps_drop_outside = 0;
  double snaps_matrix_threshold = 0.15;
  std::string snaps_images;               // empty: Images_path
  double snaps_thumbnail_scale = 1.0 / 6.0;
  int snaps_window = 8;
  double snaps_min_similarity = 0.75;
  double snaps_yaw_limit = 10.0;
  double snaps_radius = 10.0;
  int snaps_frame_distance = 100;
  int snaps_attempts = 10;
  int snaps_discount_length = 300;
  int snaps_pause = 20;
  std::string snaps_corrector = "both";   // discounted, pose-graph, both
  double snaps_loop_weight = 1.0;
  double snaps_odometry_translation_weight = 2500.0;
  double snaps_odometry_rotation_weight = 1e6;
  std::string snaps_robust_kernel = "huber";
  double snaps_robust_scale = 3.0;
  std::string snaps_axes = "xz";
  std::string snaps_output_name;
  std::string snaps_odometry;             // "", mono, stereo
  // --- Odometry (new; openable_snaps with Snaps_odometry, docs/odometry.md) --------------------
  std::string odometry_calibration;
  double odometry_calibration_scale = 1.0;
  std::string odometry_scale = "truth";   // truth, step, none
  double odometry_step_length = 1.0;
  std::string odometry_features;          // empty: the odometry's default (SIFT)
  int odometry_max_features = 2000;
  double odometry_ratio_test = 0.8;
  double odometry_ransac_threshold = 0.0;  // 0: the odometry's default
  int odometry_min_inliers = 0;           // 0: the odometry's default
  std::string odometry_matcher = "sgbm";
  int odometry_wls_filter = 1;
  int odometry_num_disparities = 64;
  double odometry_max_depth = 80.0;

  bool operator==(const Config& other) const;
  bool operator!=(const Config& other) const { return !(*this == other); }
};

// Where a value came from, for error messages: "Config.txt:12" or "--set".
struct ConfigSource {
  std::string where;
};

// Reads a configuration file: the flat "Key: value" subset of YAML that the original's
// OpenCV FileStorage files use ("%YAML:1.0" first line optional, '#' comments, strings quoted
// or not). Keys not present keep their defaults. Throws InputError with one line
// "<file>:<line>: <Key>: <problem>" on a missing or unreadable file, a line that is not
// "Key: value", an unknown key (naming the nearest valid one), a duplicated key, or a value
// of the wrong type or out of range.
Config LoadConfig(const std::string& path);

// The parser of LoadConfig on the text of a configuration already in memory; `name` stands
// for the file in messages ("<name>:<line>: ..."). Same checks, same InputError messages.
Config ParseConfigText(const std::string& text, const std::string& name);

// Applies one "Key=Value" override (from --set). Same checks and messages as LoadConfig.
void ApplyOverride(Config& config, const std::string& assignment);

// Cross-key checks that no single value shows (the mode's inputs are given, the threshold is
// -1 or in [0, 1], parts not built yet are asked for, ...). Throws InputError naming the key.
void CheckConfig(const Config& config);

// The layer radii of Side_window_radii ("1,2,3": integers in [1, 50], 1 to 16 layers, spaces
// allowed). Throws a one-line InputError naming the key otherwise.
std::vector<int> ParseSideWindowRadii(const std::string& text);

// Cross-key checks of the SNAPS keys (openable_snaps): a trajectory is given, the format,
// loop source, corrector, robust kernel and axes names are known, the file a loop source
// reads is given, and Snaps_images or Images_path for the search. Throws InputError naming
// the key, the value and what was expected.
void CheckSnapsConfig(const Config& config);

// The checks of CheckConfig on the Evaluation keys alone (Ground_truth_type known, its file
// given, heading, radius and axes valid), for tools that only evaluate.
void CheckEvaluationConfig(const Config& config);

// Writes `config` in the same format LoadConfig reads (every key, with a comment each).
std::string FormatConfig(const Config& config);

// The keys for --help: grouped, one entry per key with its meaning, default and range.
std::string ConfigHelpText();

// The same information as a Markdown table, for docs/configuration.md.
std::string ConfigMarkdownReference();

// The value of `key` as FormatConfig writes it (strings quoted). Throws std::logic_error for
// an unknown key.
std::string ConfigValueText(const Config& config, const std::string& key);

// Every key name, in table order.
std::vector<std::string> ConfigKeyNames();

}  // namespace openable
