#include "config/config.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

// One key, bound once. `min`/`max` bound numbers; `choices` names the meaning of each
// allowed integer value (shown in --help), when the key is an enumeration.
struct Binding {
  const char* key;
  const char* group;
  std::variant<int Config::*, double Config::*, std::string Config::*> field;
  double min;
  double max;
  const char* meaning;
  bool is_new;
};

constexpr double kNoLimit = std::numeric_limits<double>::infinity();

// The table. Order = order in --help, in FormatConfig and in docs/configuration.md.
const std::vector<Binding>& Bindings() {
  static const std::vector<Binding> table = {
      // Datasets
      {"Frame_mode", "Datasets", &Config::frame_mode, 0, 2,
       "Input: 0 image folder(s) (Images_path, optionally Images_path_2), 1 one video "
       "(Video_path_1), 2 two videos matched as one concatenated sequence (Video_path_1, "
       "Video_path_2).",
       false},
      {"Images_path", "Datasets", &Config::images_path, 0, 0,
       "Folder of the image sequence (Frame_mode 0). Any file names: frames are taken in "
       "natural order (img2 before img10). PNG, JPEG, TIFF, PGM/PPM, BMP; 8 or 16 bit; grey "
       "or colour. Relative paths are relative to the working directory.",
       false},
      {"Images_path_2", "Datasets", &Config::images_path_2, 0, 0,
       "Folder of a second traversal of the route (Frame_mode 0). The matrix covers both "
       "sequences concatenated (Images_path first), so its lower-left block holds every frame "
       "of this folder (rows) against every frame of Images_path (columns). Empty: one "
       "sequence.",
       true},
      {"Images_path_left", "Datasets", &Config::images_path_left, 0, 0,
       "Left image folder of a stereo camera (Camera_type 1; Images_path is then not used). "
       "Same Images_format and Initial_image/Final_image range as Images_path; the frame "
       "names of the run are the left file names.",
       false},
      {"Images_path_right", "Datasets", &Config::images_path_right, 0, 0,
       "Right image folder of a stereo camera (Camera_type 1). Must hold as many images as "
       "Images_path_left: pairs are matched by position in natural order.",
       false},
      {"Calibration_path", "Datasets", &Config::calibration_path, 0, 0,
       "Stereo calibration file (Camera_type 1), OpenCV YAML as the original: ML, MR, DL, "
       "DR, R, T, optional colormap and use_log (docs/cameras.md).",
       false},
      {"Images_format", "Datasets", &Config::images_format, 0, 0,
       "Extension of the images to take from the folders (e.g. png); empty takes every "
       "supported image file. Unlike the original, names need not be %06d.<ext>.",
       false},
      {"Video_path_1", "Datasets", &Config::video_path_1, 0, 0,
       "Video file read with OpenCV (Frame_mode 1 and 2).", false},
      {"Video_path_2", "Datasets", &Config::video_path_2, 0, 0,
       "Second video file (Frame_mode 2), concatenated after Video_path_1.", false},
      {"Initial_image", "Datasets", &Config::initial_image, 0, kNoLimit,
       "First frame to process: a 0-based position in the natural order of the folder's "
       "images (or the video's frames). Applies to every folder or video of the run.",
       false},
      {"Final_image", "Datasets", &Config::final_image, -1, kNoLimit,
       "One past the last frame to process (a position, as Initial_image); -1 processes to "
       "the end.",
       false},
      {"Skip_unreadable", "Datasets", &Config::skip_unreadable, 0, 1,
       "0 stops at the first frame that cannot be read, naming it; 1 skips such frames with "
       "a warning (the matrix then has fewer rows, and the skipped frames are listed).",
       true},
      // Representation
      {"Txt_name", "Representation", &Config::txt_name, 0, 0,
       "Output: the normalised matrix M' (or M'' when Threshold is set, as the original) as "
       "space-separated text, one row per line. Empty: not written (text is slow and large "
       "for long runs).",
       false},
      {"Npy_name", "Representation", &Config::npy_name, 0, 0,
       "Output: the normalised matrix M' (before any threshold) as a float32 NumPy .npy "
       "file (numpy.load reads it). Empty: not written.",
       true},
      {"Png_name", "Representation", &Config::png_name, 0, 0,
       "Output: the normalised matrix M' as a colour image, one pixel per pair of frames, "
       "coloured with Matrix_color. Empty: not written.",
       false},
      {"Png_threshold_name", "Representation", &Config::png_threshold_name, 0, 0,
       "Output when Threshold is set: the thresholded matrix M'' as an image, coloured with "
       "Matrix_color at 0 (loop candidate, M' < Threshold) and 1 (not): black and white with "
       "map 0. Empty: Png_name with _thresholded before the extension.",
       true},
      {"Matrix_color", "Representation", &Config::matrix_color, 0, 11,
       "Colour map of Png_name, as the original's 12 maps (docs/output_formats.md): 0 grey, "
       "1 red, 2 green, 3 blue, 4-11 two-colour ramps.",
       false},
      {"Show_images", "Representation", &Config::show_images, 0, 1,
       "1 shows each frame in a window while it is described (needs a display; ignored with "
       "a warning when there is none).",
       false},
      // Description and matching
      {"Camera_type", "Description and matching", &Config::camera_type, 0, 2,
       "0 monocular (ABLE-M); 1 stereo (ABLE-S): pairs of Images_path_left and "
       "Images_path_right are rectified with Calibration_path and matched (SGBM) for D-LDB; "
       "other descriptors describe the rectified left image (docs/cameras.md). 2 panoramic "
       "(ABLE-P): each frame is a 360-degree panorama cut into Panoramas sub-panoramas, "
       "compared as Panorama_matching says.",
       false},
      {"Description_type", "Description and matching", &Config::description_type, 0, 1,
       "0 global: the frame is resized to Patch_size x Patch_size and described at its centre; "
       "1 grid: the frame is cut into Grid_x x Grid_y cells, each resized to Patch_size and "
       "described at its centre, and the descriptors are concatenated.",
       false},
      {"Patch_size", "Description and matching", &Config::patch_size, 16, 1024,
       "Side of the square patch in pixels (64 in the ABLE papers). HOG needs a multiple of "
       "8. Used as given for every descriptor (the original forced 128 for ORB).",
       false},
      {"Grid_x", "Description and matching", &Config::grid_x, 1, 64,
       "Grid cells across the frame (Description_type 1).", false},
      {"Grid_y", "Description and matching", &Config::grid_y, 1, 64,
       "Grid cells down the frame (Description_type 1).", false},
      {"Panoramas", "Description and matching", &Config::panoramas, 1, 64,
       "Sub-panoramas (equal-width vertical strips) of a panoramic frame (Camera_type 2), each "
       "described on its own (global or grid) and concatenated. An even number makes a "
       "half-turn (the route driven the other way) a whole number of strips.",
       false},
      {"Panorama_matching", "Description and matching", &Config::panorama_matching, 0, 2,
       "Camera_type 2: how two panoramas are compared. 0 aligned (ABLE-P Eq. 2: strip k "
       "against strip k; same-direction revisits only); 1 cross-correlation (Eq. 3, 4: the "
       "smallest distance over every pair of strips; finds revisits in the opposite "
       "direction); 2 circular (the whole panorama turned by the best whole number of "
       "strips).",
       true},
      {"Illumination_invariance", "Description and matching", &Config::illumination_invariance,
       0, 1,
       "1 describes the illumination invariant image of Eq. 6, I = log G - Alpha log B - "
       "(1 - Alpha) log R, instead of the grey image. Needs colour frames (an error names the "
       "first grey one).",
       false},
      {"Alpha", "Description and matching", &Config::alpha, 0, 1,
       "Alpha of Eq. 6 (0.47 for KITTI's PointGrey Flea2). Replaced by Eq. 7 when Lambda_red, "
       "Lambda_green and Lambda_blue are given.",
       false},
      {"Lambda_red", "Description and matching", &Config::lambda_red, 0, 2000,
       "Peak spectral response of the red channel, nm (camera data sheet); with Lambda_green "
       "and Lambda_blue it sets Alpha by Eq. 7. 0 = not given (all three or none).",
       true},
      {"Lambda_green", "Description and matching", &Config::lambda_green, 0, 2000,
       "Peak spectral response of the green channel, nm; see Lambda_red.", true},
      {"Lambda_blue", "Description and matching", &Config::lambda_blue, 0, 2000,
       "Peak spectral response of the blue channel, nm; see Lambda_red.", true},
      {"Image_descriptor", "Description and matching", &Config::image_descriptor, 0, 0,
       "LDB, D-LDB (LDB of the grey and of the disparity image; needs Camera_type 1), ORB, "
       "BRISK, BRIEF, FREAK (binary, Hamming distance) or SIFT, HOG (vector, L2 distance). "
       "SURF is not available (non-free, absent from Debian's OpenCV).",
       false},
      {"Image_sequences", "Description and matching", &Config::image_sequences, 1, 100000,
       "Sequence length L: the distance of two places sums L single-frame distances along "
       "the diagonal; 1 = single images. Frames with fewer than L predecessors in their "
       "traversal use the available terms scaled to L.",
       false},
      {"Threshold", "Description and matching", &Config::threshold, -1, 1,
       "Theta of Eq. 9: M'' = 0 where M' < Threshold, 1 elsewhere. -1 disables; otherwise "
       "in [0, 1].",
       false},
      {"Ldb_bits", "Description and matching", &Config::ldb_bits, 1, 1386,
       "Bits of the LDB descriptor (256 = 32 bytes, as in ABLE-P; 1386 = every test of the "
       "2x2 to 5x5 grids). See docs/descriptors.md for the selection.",
       true},
      {"Threads", "Description and matching", &Config::threads, 0, 1024,
       "Worker threads for description and matching; 0 = all cores.", true},
      {"Sequence_direction", "Description and matching", &Config::sequence_direction, 0, 2,
       "0 sums along diagonals (both routes driven the same way, the original); 1 along "
       "anti-diagonals (the reference route driven the opposite way); 2 the smaller of the "
       "two for every cell (needs a second matrix in dense mode).",
       true},
      // Robustness
      {"Side_window", "Robustness", &Config::side_window, 0, 1,
       "1 applies side-window multilayer pixel fusion to the grey image before description "
       "(Algorithm 1 of the side-window direct SLAM paper): in every layer each pixel becomes "
       "the mean of the one of its eight side windows (U, D, L, R, NW, NE, SW, SE) closest to "
       "it, which smooths noise but keeps edges. 0 = off. See docs/descriptors.md.",
       true},
      {"Side_window_radii", "Robustness", &Config::side_window_radii, 0, 0,
       "Radius of each side-window layer, in order, comma-separated (\"1,2,3\": three layers, "
       "windows of 2x3 to 4x7 pixels); integers in [1, 50], 1 to 16 layers. Used when "
       "Side_window is 1.",
       true},
      {"Noise_gaussian", "Robustness", &Config::noise_gaussian, 0, 1,
       "Robustness studies: variance of the Gaussian noise added to every frame's intensities "
       "in [0, 1] (per channel, then clipped to [0, 1]) before grey conversion; the "
       "side-window paper uses 0.003. 0 = off.",
       true},
      {"Noise_salt_pepper", "Robustness", &Config::noise_salt_pepper, 0, 1,
       "Robustness studies: fraction of the pixels of every frame set to black or white (even "
       "odds), after the Gaussian noise; the side-window paper uses 0.1. 0 = off.",
       true},
      {"Noise_overexposure", "Robustness", &Config::noise_overexposure, 0, kNoLimit,
       "Robustness studies: overexposure of every frame, intensities v in [0, 1] multiplied "
       "by 1 + this value and saturated at 1 (1 doubles the exposure: everything above 0.5 "
       "becomes white). Applied first. 0 = off.",
       true},
      {"Noise_seed", "Robustness", &Config::noise_seed, 0, 1000000000,
       "Seed of the noise: each frame's noise depends only on this seed, its traversal and "
       "its index, so a run is repeatable whatever the number of Threads.",
       true},
      // Scale
      {"Matrix_mode", "Scale", &Config::matrix_mode, 0, 2,
       "0 auto: dense when the N x N matrix fits in Memory_limit, bounded otherwise (the run "
       "says which and why); 1 dense: the whole matrix, every output; 2 bounded: the matrix "
       "is computed in tiles of rows and only the matches of Best_matches and Band_width are "
       "kept (Matches_name); with two traversals only queries (Images_path_2) against "
       "references (Images_path) are computed.",
       true},
      {"Memory_limit", "Scale", &Config::memory_limit, 0, kNoLimit,
       "GiB the dense matrices may take before auto mode switches to bounded; 0 = three "
       "quarters of the machine's memory.",
       true},
      {"Best_matches", "Scale", &Config::best_matches, 0, 100000,
       "k: the k smallest distances of every query are kept in Matches_name (one "
       "sequence: among frames at least Exclusion frames earlier). 0 keeps none.",
       true},
      {"Band_width", "Scale", &Config::band_width, -1, kNoLimit,
       "Also keep every cell with |i - j| <= Band_width, frames counted from the start of "
       "each traversal (aligned traversals); -1 keeps no band.",
       true},
      {"Matches_name", "Scale", &Config::matches_name, 0, 0,
       "Kept matches: .npy (structured: query, reference int32; distance float32 = M'; rank "
       "int32, 1 = best, 0 = band only) or .csv. Frame numbers count from the start of their "
       "traversal. Required in bounded mode; optional in dense mode (taken from the matrix).",
       true},
      {"Approximate_search", "Scale", &Config::approximate_search, 0, 1,
       "1: bounded mode finds the Best_matches candidates of each query with FLANN (LSH for "
       "binary descriptors, k-d trees for vector ones) instead of comparing every pair, then "
       "scores them with the sequence sum; faster on very large runs, recall below 1 "
       "(docs/benchmarks.md). No band.",
       true},
      {"Approximate_checks", "Scale", &Config::approximate_checks, 1, 100000,
       "FLANN k-d trees (vector descriptors): references examined per query (more: better "
       "recall, slower; LSH for binary descriptors ignores it).", true},
      {"Descriptor_cache", "Scale", &Config::descriptor_cache, 0, 0,
       "Folder of the descriptor cache; empty = off. Each frame's descriptor row is kept "
       "under a hash of the image file's bytes and of every setting that changes the row "
       "(docs/output_formats.md), so a run interrupted or repeated with the same description "
       "settings describes only the frames not cached, and gives the same matrix bit for bit. "
       "Image folders only (not videos or stereo pairs). Created when missing.",
       true},
      // Evaluation (docs/evaluation.md)
      {"Ground_truth_type", "Evaluation", &Config::ground_truth_type, 0, 0,
       "Empty: no evaluation. matrix (0/1 text, image, .npy), pairs (CSV or whitespace "
       "row,col), aligned (two traversals, query i is reference i), kitti (3x4 poses), tum "
       "(timestamp tx ty tz qx qy qz qw), positions (x,y[,z]): the run's matrix is evaluated "
       "against it with both protocols of docs/evaluation.md.",
       true},
      {"Ground_truth", "Evaluation", &Config::ground_truth, 0, 0,
       "Ground-truth file (not needed for aligned). Pairs and poses count frames from the "
       "start of the source, as Initial_image does; for poses of two traversals, the poses "
       "of the reference (Images_path).",
       true},
      {"Ground_truth_2", "Evaluation", &Config::ground_truth_2, 0, 0,
       "Poses of the query traversal (Images_path_2 or Video_path_2) for kitti, tum and "
       "positions ground truth of two traversals.",
       true},
      {"Ground_truth_base", "Evaluation", &Config::ground_truth_base, -1, 1,
       "Pairs: 0 or 1 for 0- or 1-based frame numbers; -1 reads a comment line saying "
       "\"0-based\" or \"1-based\", else 0.",
       true},
      {"Ground_truth_radius", "Evaluation", &Config::ground_truth_radius, 0, kNoLimit,
       "Poses: two frames are the same place when their positions are closer than this (the "
       "poses' unit, metres for KITTI).",
       true},
      {"Ground_truth_heading", "Evaluation", &Config::ground_truth_heading, -1, 180,
       "Poses: and when their viewing directions differ by less than this many degrees (a "
       "forward camera cannot recognise a place seen the other way); -1: no limit.",
       true},
      {"Ground_truth_min_gap", "Evaluation", &Config::ground_truth_min_gap, -1, kNoLimit,
       "Poses, one sequence: only frames at least this many frames apart are loops; -1: "
       "Exclusion.",
       true},
      {"Ground_truth_axes", "Evaluation", &Config::ground_truth_axes, 0, 0,
       "Poses: axes of the distance and heading: xyz (3D), xz (the ground plane of KITTI's "
       "camera frame, y down) or xy.",
       true},
      {"Tolerance", "Evaluation", &Config::tolerance, 0, kNoLimit,
       "Frames: a best match within this many frames of a true match is correct (2 for "
       "Nordland and Gardens Point, 3 for KITTI in docs/benchmarks.md).",
       true},
      {"Exclusion", "Evaluation", &Config::exclusion, 1, kNoLimit,
       "One sequence: the candidates of frame q are frames at least this many frames "
       "earlier (recent frames always look alike and are not loops).",
       true},
      {"Vicinity", "Evaluation", &Config::vicinity, 0, kNoLimit,
       "ABLE-P protocol: a detected cell is a true positive when a ground-truth loop lies "
       "within this many frames of it in both directions (7 in the ABLE-P paper).",
       true},
      {"Evaluation_name", "Evaluation", &Config::evaluation_name, 0, 0,
       "Output prefix of the evaluation: <name>.json (figures and settings), "
       "<name>_per_query.csv and <name>_ablep.csv (curves), <name>_pr.png (precision-recall "
       "figure), <name>_overlay.png (ground truth and best matches over the matrix). Empty: "
       "the figures are printed only.",
       true},
      {"Evaluation_label", "Evaluation", &Config::evaluation_label, 0, 0,
       "Name of this run in the figure's legend and the JSON; empty: descriptor and L, "
       "e.g. \"LDB L=10\".",
       true},
      // SNAPS add-on (openable_snaps; docs/snaps.md)
      {"Snaps_trajectory", "SNAPS", &Config::snaps_trajectory, 0, 0,
       "openable_snaps: the drifting trajectory to correct (visual odometry), in "
       "Snaps_trajectory_format.",
       true},
      {"Snaps_odometry", "SNAPS", &Config::snaps_odometry, 0, 0,
       "Empty: read Snaps_trajectory. mono: compute it from the images (Snaps_images or "
       "Images_path) with the monocular odometry (docs/odometry.md; the scale comes from "
       "Odometry_scale); stereo: from Images_path_left and Images_path_right (rectified with "
       "Calibration_path, or already rectified with Odometry_calibration). The computed "
       "trajectory is written as <Snaps_output_name>_odometry.txt (KITTI format).",
       true},
      {"Snaps_trajectory_format", "SNAPS", &Config::snaps_trajectory_format, 0, 0,
       "kitti (12 numbers per line, pose i = frame i), kitti-id (frame number + 12 numbers: "
       "keyframes) or tum (timestamp tx ty tz qx qy qz qw). The corrected trajectories are "
       "written in the same format.",
       true},
      {"Snaps_world_to_camera", "SNAPS", &Config::snaps_world_to_camera, 0, 1,
       "1: the trajectory file holds world-to-camera matrices (SO-DSO's "
       "poses_history_file.txt); they are inverted on reading and again on writing.",
       true},
      {"Snaps_ground_truth", "SNAPS", &Config::snaps_ground_truth, 0, 0,
       "Ground-truth trajectory (camera-to-world) for the error figures and the plot; empty: "
       "no evaluation. Associated by frame number (kitti, kitti-id) or timestamp (tum).",
       true},
      {"Snaps_ground_truth_format", "SNAPS", &Config::snaps_ground_truth_format, 0, 0,
       "Format of Snaps_ground_truth: kitti, kitti-id or tum.", true},
      {"Snaps_time_tolerance", "SNAPS", &Config::snaps_time_tolerance, 0, kNoLimit,
       "tum: a pose and its ground truth are associated when their timestamps differ by at "
       "most this many seconds.",
       true},
      {"Snaps_loops", "SNAPS", &Config::snaps_loops, 0, 0,
       "Where the loops come from: search (SNAPS's own search on thumbnails of Snaps_images, "
       "run online with the discounted update, as the paper), openable (an OpenABLE run on "
       "the same images with the description keys of this file: each frame's best match at "
       "least Snaps_frame_distance frames back, kept below Snaps_matrix_threshold), pairs (Snaps_loops_file: "
       "row,col frame numbers per line, row the later frame), matrix (Snaps_loops_file: the "
       "normalised matrix of an OpenABLE run of one sequence, .npy/.txt/image: each frame's "
       "best match at least Snaps_frame_distance frames back, kept below "
       "Snaps_matrix_threshold).",
       true},
      {"Snaps_loops_file", "SNAPS", &Config::snaps_loops_file, 0, 0,
       "Pairs file (Snaps_loops pairs) or saved matrix (Snaps_loops matrix).", true},
      {"Snaps_keyframe_tolerance", "SNAPS", &Config::snaps_keyframe_tolerance, 0, kNoLimit,
       "Snaps_loops pairs and matrix: a frame that is not a pose of the trajectory (keyframes) "
       "takes the nearest pose within this many frames; 0 keeps only frames that are poses.",
       true},
      {"Snaps_drop_outside", "SNAPS", &Config::snaps_drop_outside, 0, 1,
       "Snaps_loops pairs: 0 stops at a pair with a frame outside the trajectory's frames (an "
       "error naming the line); 1 drops such pairs and says how many (a ground-truth list of a "
       "whole sequence against a trajectory that stops a few frames early).",
       true},
      {"Snaps_middle_of_runs", "SNAPS", &Config::snaps_middle_of_runs, 0, 1,
       "Snaps_loops pairs: 1 keeps, of each query's references, only the middle of each run of "
       "consecutive frames (ground-truth lists pair a query with every frame within a radius; "
       "the middle is the nearest place); 0 keeps every pair.",
       true},
      {"Snaps_matrix_threshold", "SNAPS", &Config::snaps_matrix_threshold, 0, 1,
       "Snaps_loops matrix: a best match is a loop when its normalised distance M' is below "
       "this; its similarity Q is 1 - M'.",
       true},
      {"Snaps_images", "SNAPS", &Config::snaps_images, 0, 0,
       "Snaps_loops search: image folder of the trajectory's frames (image i in natural order "
       "is frame i); empty: Images_path.",
       true},
      {"Snaps_thumbnail_scale", "SNAPS", &Config::snaps_thumbnail_scale, 0.01, 1,
       "Thumbnails are the frames scaled by this (1/6 in the paper).", true},
      {"Snaps_window", "SNAPS", &Config::snaps_window, 2, 64,
       "B: side of the sliding window of the universal image quality index (Eq. 4, 5); the "
       "paper gives none, 8 is Wang and Bovik's.",
       true},
      {"Snaps_min_similarity", "SNAPS", &Config::snaps_min_similarity, -1, 1,
       "Minimum similarity Q of a loop (0.75 in the paper).", true},
      {"Snaps_yaw_limit", "SNAPS", &Config::snaps_yaw_limit, 0, 180,
       "Candidates whose heading differs from the current frame's by more than this many "
       "degrees are ignored (10 in the paper).",
       true},
      {"Snaps_radius", "SNAPS", &Config::snaps_radius, 0, kNoLimit,
       "Candidates lie within this many metres of the current (corrected) position (not "
       "given in the paper).",
       true},
      {"Snaps_frame_distance", "SNAPS", &Config::snaps_frame_distance, 1, kNoLimit,
       "M: the last M frames are never candidates (frame numbers of the trajectory's poses; "
       "not given in the paper).",
       true},
      {"Snaps_attempts", "SNAPS", &Config::snaps_attempts, 1, kNoLimit,
       "At most this many candidates, nearest first, are compared (not given in the paper).",
       true},
      {"Snaps_discount_length", "SNAPS", &Config::snaps_discount_length, 0, kNoLimit,
       "K of Eq. 6: the last K poses move towards the reference (not given in the paper; "
       "gamma is 0 beyond 300 poses for the first loop).",
       true},
      {"Snaps_pause", "SNAPS", &Config::snaps_pause, 0, kNoLimit,
       "Inter-frame pause: no loop is closed within this many poses after the last one (not "
       "given in the paper).",
       true},
      {"Snaps_corrector", "SNAPS", &Config::snaps_corrector, 0, 0,
       "discounted (the paper's Eq. 6), pose-graph (least squares over odometry and loop "
       "edges) or both.",
       true},
      {"Snaps_loop_weight", "SNAPS", &Config::snaps_loop_weight, 0, kNoLimit,
       "Pose graph: information of a loop edge's position residual, 1/m^2 (1 = sigma 1 m).",
       true},
      {"Snaps_odometry_translation_weight", "SNAPS", &Config::snaps_odometry_translation_weight,
       0, kNoLimit,
       "Pose graph: information of an odometry edge's translation per pose step, 1/m^2 (2500 "
       "= sigma 0.02 m).",
       true},
      {"Snaps_odometry_rotation_weight", "SNAPS", &Config::snaps_odometry_rotation_weight, 0,
       kNoLimit,
       "Pose graph: information of an odometry edge's rotation per pose step, 1/rad^2 (1e6 = "
       "sigma 0.001 rad).",
       true},
      {"Snaps_robust_kernel", "SNAPS", &Config::snaps_robust_kernel, 0, 0,
       "Pose graph: robust kernel on loop edges, none, huber or cauchy (a few wrong loops then "
       "pull with a bounded force).",
       true},
      {"Snaps_robust_scale", "SNAPS", &Config::snaps_robust_scale, 0, kNoLimit,
       "Pose graph: scale of the robust kernel in sigmas of a loop edge.", true},
      {"Snaps_axes", "SNAPS", &Config::snaps_axes, 0, 0,
       "Ground plane of the plot and of the yaw: xz (KITTI: y points down) or xy (z up).",
       true},
      // Odometry (openable_snaps with Snaps_odometry; docs/odometry.md)
      {"Odometry_calibration", "Odometry", &Config::odometry_calibration, 0, 0,
       "KITTI calib.txt (P0, P1 lines) of rectified images: the intrinsics (P0) and, for "
       "stereo, the baseline (P1). Stereo may use Calibration_path instead (raw pairs, "
       "rectified here).",
       true},
      {"Odometry_calibration_scale", "Odometry", &Config::odometry_calibration_scale, 0.01, 10,
       "Multiplies the focal lengths and principal point of Odometry_calibration (0.5 for "
       "images at half the calibrated size, as the shared KITTI frames).",
       true},
      {"Odometry_scale", "Odometry", &Config::odometry_scale, 0, 0,
       "mono: where the length of each step comes from, since one camera cannot measure it: "
       "truth (the step lengths of Snaps_ground_truth), step (Odometry_step_length every "
       "frame) or none (unit steps: the trajectory's scale is arbitrary).",
       true},
      {"Odometry_step_length", "Odometry", &Config::odometry_step_length, 0, kNoLimit,
       "mono with Odometry_scale step: metres travelled between two frames (speed / frame "
       "rate).",
       true},
      {"Odometry_features", "Odometry", &Config::odometry_features, 0, 0,
       "ORB or SIFT; empty: SIFT (the paper's; also the better one for the monocular "
       "odometry on KITTI, docs/odometry.md).",
       true},
      {"Odometry_max_features", "Odometry", &Config::odometry_max_features, 10, kNoLimit,
       "Features detected per frame.", true},
      {"Odometry_ratio_test", "Odometry", &Config::odometry_ratio_test, 0.1, 1,
       "Lowe's ratio test on the two nearest descriptors.", true},
      {"Odometry_ransac_threshold", "Odometry", &Config::odometry_ransac_threshold, 0, 100,
       "RANSAC inlier threshold, pixels (mono: distance to the epipolar line, default 0.5; "
       "stereo: PnP reprojection error, default 2); 0 keeps the default.",
       true},
      {"Odometry_min_inliers", "Odometry", &Config::odometry_min_inliers, 0, kNoLimit,
       "Fewer inliers: the step keeps the previous motion (constant velocity) and is counted "
       "as failed in the report (default 20 mono, 15 stereo; 0 keeps the default).",
       true},
      {"Odometry_matcher", "Odometry", &Config::odometry_matcher, 0, 0,
       "stereo: disparity by sgbm or bm (block matching, as the paper).", true},
      {"Odometry_wls_filter", "Odometry", &Config::odometry_wls_filter, 0, 1,
       "stereo: 1 filters the disparity with the weighted-least-squares filter (the paper).",
       true},
      {"Odometry_num_disparities", "Odometry", &Config::odometry_num_disparities, 16, 1024,
       "stereo: disparity search range, pixels (a multiple of 16).", true},
      {"Odometry_max_depth", "Odometry", &Config::odometry_max_depth, 1, kNoLimit,
       "stereo: points farther than this many metres are not used in PnP.", true},
      {"Snaps_output_name", "SNAPS", &Config::snaps_output_name, 0, 0,
       "Output prefix: <name>_discounted.txt and/or <name>_pose_graph.txt (the corrected "
       "trajectories), <name>_loops.csv, <name>.json (figures), <name>.png (plot). Empty: "
       "figures printed only.",
       true},
  };
  return table;
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// Edit distance, for "did you mean".
int Levenshtein(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

const Binding* Find(const std::string& key) {
  for (const auto& b : Bindings())
    if (key == b.key) return &b;
  return nullptr;
}

std::string Nearest(const std::string& key) {
  std::string best;
  int best_d = std::numeric_limits<int>::max();
  for (const auto& b : Bindings()) {
    const int d = Levenshtein(Lower(key), Lower(b.key));
    if (d < best_d) best_d = d, best = b.key;
  }
  return best_d <= std::max<int>(3, static_cast<int>(key.size()) / 3) ? best : "";
}

// Quoted (error.h): quotes and control characters escaped, so that a message quoting a line
// of a binary file stays one readable line.
std::string Quote(const std::string& v) { return Quoted(v); }

std::string FormatNumber(double v) {
  if (std::isinf(v)) return "inf";
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string RangeText(const Binding& b) {
  if (std::holds_alternative<std::string Config::*>(b.field)) return "text";
  const bool is_int = std::holds_alternative<int Config::*>(b.field);
  const char* kind = is_int ? "integer" : "number";
  if (std::isinf(b.max)) return std::string(kind) + " >= " + FormatNumber(b.min);
  return std::string(kind) + " in [" + FormatNumber(b.min) + ", " + FormatNumber(b.max) + "]";
}

std::string ValueText(const Config& c, const Binding& b) {
  if (auto p = std::get_if<int Config::*>(&b.field)) return std::to_string(c.**p);
  if (auto p = std::get_if<double Config::*>(&b.field)) return FormatNumber(c.**p);
  return "\"" + c.*std::get<std::string Config::*>(b.field) + "\"";  // as FormatConfig writes it
}

// Strips the quotes of a YAML scalar ("..." or '...'); unquoted text is taken as is.
std::string Unquote(const std::string& v, const std::string& where, const std::string& key) {
  if (v.size() >= 1 && (v.front() == '"' || v.front() == '\'')) {
    if (v.size() < 2 || v.back() != v.front())
      throw InputError(where + ": " + key + ": unterminated quoted value " + v);
    return v.substr(1, v.size() - 2);
  }
  return v;
}

void Assign(Config& c, const Binding& b, const std::string& raw, const std::string& where) {
  const std::string value = Unquote(raw, where, b.key);
  auto fail = [&](const std::string& expected) {
    throw InputError(where + ": " + b.key + ": value " + Quote(value) + " is not valid; expected " +
                     expected);
  };
  if (auto p = std::get_if<std::string Config::*>(&b.field)) {
    c.**p = value;
    return;
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  if (value.empty() || end != value.c_str() + value.size() || errno == ERANGE || !std::isfinite(v))
    fail(RangeText(b));
  if (auto p = std::get_if<int Config::*>(&b.field)) {
    if (v != std::floor(v)) fail(RangeText(b));
    if (v < b.min || v > b.max || std::fabs(v) > std::numeric_limits<int>::max()) fail(RangeText(b));
    c.**p = static_cast<int>(v);
  } else {
    if (v < b.min || v > b.max) fail(RangeText(b));
    c.*std::get<double Config::*>(b.field) = v;
  }
}

const Binding& Lookup(const std::string& key, const std::string& where) {
  if (const Binding* b = Find(key)) return *b;
  const std::string near = Nearest(key);
  throw InputError(where + ": unknown key " + Quote(key) +
                   (near.empty() ? "" : "; did you mean " + Quote(near) + "?") +
                   " (Test_OpenABLE --help lists every key)");
}

// Removes a '#' comment that is not inside quotes.
std::string StripComment(const std::string& line) {
  char quote = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const char ch = line[i];
    if (quote) {
      if (ch == quote) quote = 0;
    } else if (ch == '"' || ch == '\'') {
      quote = ch;
    } else if (ch == '#') {
      return line.substr(0, i);
    }
  }
  return line;
}

}  // namespace

bool Config::operator==(const Config& o) const {
  for (const auto& b : Bindings())
    if (ValueText(*this, b) != ValueText(o, b)) return false;
  return true;
}

void CheckSnapsConfig(const Config& c) {
  auto one_of = [](const std::string& key, const std::string& value,
                   std::initializer_list<const char*> choices) {
    std::string list;
    for (const char* choice : choices) {
      if (Lower(value) == choice) return;
      list += (list.empty() ? "" : ", ") + std::string(choice);
    }
    throw InputError(key + ": " + Quote(value) + " is not valid; expected one of " + list);
  };
  one_of("Snaps_odometry", c.snaps_odometry, {"", "mono", "stereo"});
  const std::string odometry = Lower(c.snaps_odometry);
  if (odometry.empty() && c.snaps_trajectory.empty())
    throw InputError("Snaps_trajectory: empty; expected the path of the trajectory to correct "
                     "(or Snaps_odometry mono or stereo to compute it from the images)");
  if (!odometry.empty()) {
    one_of("Odometry_scale", c.odometry_scale, {"truth", "step", "none"});
    one_of("Odometry_features", c.odometry_features, {"", "orb", "sift"});
    one_of("Odometry_matcher", c.odometry_matcher, {"sgbm", "bm"});
    if (c.odometry_num_disparities % 16 != 0)
      throw InputError("Odometry_num_disparities: " + std::to_string(c.odometry_num_disparities) +
                       " is not valid; expected a multiple of 16");
    if (odometry == "mono" && c.odometry_calibration.empty())
      throw InputError("Odometry_calibration: empty; expected the camera's KITTI calib.txt "
                       "for Snaps_odometry mono");
    if (odometry == "mono" && Lower(c.odometry_scale) == "truth" && c.snaps_ground_truth.empty())
      throw InputError("Odometry_scale: truth needs Snaps_ground_truth (its step lengths give "
                       "the scale); expected a ground truth, or Odometry_scale step or none");
    if (odometry == "mono" && c.snaps_images.empty() && c.images_path.empty())
      throw InputError("Snaps_images: empty and Images_path empty; expected the image folder "
                       "of the monocular odometry");
    if (odometry == "stereo") {
      if (c.images_path_left.empty() || c.images_path_right.empty())
        throw InputError("Images_path_left, Images_path_right: expected both folders for "
                         "Snaps_odometry stereo");
      if (c.calibration_path.empty() && c.odometry_calibration.empty())
        throw InputError("Calibration_path, Odometry_calibration: both empty; expected the "
                         "stereo calibration (Calibration.txt for raw pairs, or KITTI calib.txt "
                         "for rectified pairs)");
    }
  }
  one_of("Snaps_trajectory_format", c.snaps_trajectory_format, {"kitti", "kitti-id", "tum"});
  one_of("Snaps_ground_truth_format", c.snaps_ground_truth_format, {"kitti", "kitti-id", "tum"});
  one_of("Snaps_loops", c.snaps_loops, {"search", "pairs", "matrix", "openable"});
  one_of("Snaps_corrector", c.snaps_corrector, {"discounted", "pose-graph", "both"});
  one_of("Snaps_robust_kernel", c.snaps_robust_kernel, {"none", "huber", "cauchy"});
  one_of("Snaps_axes", c.snaps_axes, {"xz", "xy"});
  const std::string loops = Lower(c.snaps_loops);
  if ((loops == "pairs" || loops == "matrix") && c.snaps_loops_file.empty())
    throw InputError("Snaps_loops_file: empty; expected the " +
                     std::string(loops == "pairs" ? "pairs file" : "saved matrix") +
                     " that Snaps_loops " + loops + " reads");
  if ((loops == "search" || loops == "openable") && c.snaps_images.empty() &&
      c.images_path.empty() && !(odometry == "stereo" && !c.images_path_left.empty()))
    throw InputError("Snaps_images: empty and Images_path empty; expected the image folder "
                     "of the trajectory's frames for Snaps_loops " + loops);
  if (c.snaps_loop_weight <= 0 || c.snaps_odometry_translation_weight <= 0 ||
      c.snaps_odometry_rotation_weight <= 0 || c.snaps_robust_scale <= 0)
    throw InputError("Snaps_loop_weight, Snaps_odometry_translation_weight, "
                     "Snaps_odometry_rotation_weight, Snaps_robust_scale: " +
                     FormatNumber(c.snaps_loop_weight) + ", " +
                     FormatNumber(c.snaps_odometry_translation_weight) + ", " +
                     FormatNumber(c.snaps_odometry_rotation_weight) + ", " +
                     FormatNumber(c.snaps_robust_scale) + "; expected every one > 0");
}

Config ParseConfigText(const std::string& contents, const std::string& name) {
  // A binary file (an image, random bytes) given as the configuration: say so in one line
  // rather than quote its first "line" of bytes. Text has no control characters but tab, CR,
  // LF and form feed.
  for (std::size_t i = 0; i < contents.size() && i < 65536; ++i) {
    const auto u = static_cast<unsigned char>(contents[i]);
    if ((u < 0x20 && u != '\t' && u != '\n' && u != '\r' && u != '\f') || u == 0x7f)
      throw InputError("configuration file " + Quote(name) + " is not text (byte " +
                       std::to_string(i) + " is " + Quote(std::string(1, contents[i])) +
                       "); expected a Config.txt of lines Key: value");
  }
  std::istringstream in(contents);
  Config config;
  std::map<std::string, int> seen;
  std::string line;
  int number = 0;
  bool any_key = false;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = name + ":" + std::to_string(number);
    std::string text = Trim(StripComment(line));
    if (number == 1 && text.rfind("\xEF\xBB\xBF", 0) == 0) text = Trim(text.substr(3));  // BOM
    if (text.empty() || text.rfind("%YAML", 0) == 0 || text == "---" || text == "...") continue;
    const auto colon = text.find(':');
    if (colon == std::string::npos || colon == 0)
      throw InputError(where + ": line " + Quote(Trim(line).substr(0, 80)) +
                       " is not of the form Key: value");
    const std::string key = Trim(text.substr(0, colon));
    const std::string value = Trim(text.substr(colon + 1));
    const Binding& b = Lookup(key, where);
    if (auto it = seen.find(key); it != seen.end())
      throw InputError(where + ": " + key + ": given twice (first at line " +
                       std::to_string(it->second) + ")");
    seen[key] = number;
    Assign(config, b, value, where);
    any_key = true;
  }
  if (!any_key)
    throw InputError("configuration file " + Quote(name) +
                     " holds no key (expected lines of the form Key: value)");
  return config;
}

Config LoadConfig(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError("configuration file " + Quote(path) +
                     " cannot be opened (expected a readable Config.txt; see Test_OpenABLE --help)");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError("configuration file " + Quote(path) + " could not be read");
  return ParseConfigText(text.str(), path);
}

void ApplyOverride(Config& config, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set: " + Quote(assignment) + " is not of the form Key=Value");
  const std::string key = Trim(assignment.substr(0, eq));
  Assign(config, Lookup(key, "--set"), Trim(assignment.substr(eq + 1)), "--set");
}

void CheckEvaluationConfig(const Config& c) {
  auto need = [](const std::string& value, const std::string& key, const std::string& why) {
    if (value.empty()) throw InputError(key + ": empty; expected a path (" + why + ")");
  };
  static const char* kTruthTypes[] = {"", "matrix", "pairs", "aligned", "kitti", "tum",
                                      "positions"};
  if (std::find(std::begin(kTruthTypes), std::end(kTruthTypes), c.ground_truth_type) ==
      std::end(kTruthTypes))
    throw InputError("Ground_truth_type: " + Quote(c.ground_truth_type) +
                     " is not a ground-truth type; expected one of matrix, pairs, aligned, "
                     "kitti, tum, positions (or empty: no evaluation)");
  if (!c.ground_truth_type.empty() && c.ground_truth_type != "aligned")
    need(c.ground_truth, "Ground_truth", "Ground_truth_type " + c.ground_truth_type + " reads a file");
  if (c.ground_truth_radius <= 0.0)
    throw InputError("Ground_truth_radius: " + FormatNumber(c.ground_truth_radius) +
                     " is not valid; expected a distance > 0");
  if (c.ground_truth_heading != -1.0 && c.ground_truth_heading <= 0.0)
    throw InputError("Ground_truth_heading: " + FormatNumber(c.ground_truth_heading) +
                     " is not valid; expected -1 (no limit) or degrees in (0, 180]");
  if (c.ground_truth_axes != "xyz" && c.ground_truth_axes != "xz" && c.ground_truth_axes != "xy")
    throw InputError("Ground_truth_axes: " + Quote(c.ground_truth_axes) +
                     " is not valid; expected xyz, xz or xy");
}

void CheckConfig(const Config& c) {
  auto need = [](const std::string& value, const std::string& key, const std::string& why) {
    if (value.empty()) throw InputError(key + ": empty; expected a path (" + why + ")");
  };
  {
    const int given = (c.lambda_red > 0) + (c.lambda_green > 0) + (c.lambda_blue > 0);
    if (given != 0 && given != 3)
      throw InputError("Lambda_red, Lambda_green, Lambda_blue: " + FormatNumber(c.lambda_red) +
                       ", " + FormatNumber(c.lambda_green) + ", " + FormatNumber(c.lambda_blue) +
                       "; expected all three peak responses (nm) or none (0)");
  }
  std::string descriptor = c.image_descriptor;
  for (char& ch : descriptor) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (descriptor == "D-LDB" && c.camera_type != 1)
    throw InputError("Image_descriptor: D-LDB needs Camera_type 1 (stereo); Camera_type is " +
                     std::to_string(c.camera_type));
  if (c.camera_type == 1) {
    if (c.frame_mode != 0)
      throw InputError("Frame_mode: " + std::to_string(c.frame_mode) +
                       " with Camera_type 1 (stereo); expected 0: stereo reads the image "
                       "folders Images_path_left and Images_path_right, not videos");
    if (!c.images_path_2.empty())
      throw InputError("Images_path_2: " + Quote(c.images_path_2) +
                       " with Camera_type 1 (stereo); expected empty: a second stereo "
                       "traversal is not supported");
    need(c.images_path_left, "Images_path_left", "Camera_type 1 reads a left image folder");
    need(c.images_path_right, "Images_path_right", "Camera_type 1 reads a right image folder");
    need(c.calibration_path, "Calibration_path", "Camera_type 1 needs a stereo calibration");
  }
  if (c.camera_type == 1 && c.illumination_invariance == 1)
    throw InputError("Illumination_invariance: 1 with Camera_type 1 (stereo); expected 0: the "
                     "stereo pipeline describes grey rectified images, and Eq. 6 needs colour");
  switch (c.frame_mode) {
    case 0:
      if (c.camera_type != 1)
        need(c.images_path, "Images_path", "Frame_mode 0 reads an image folder");
      break;
    case 1:
      need(c.video_path_1, "Video_path_1", "Frame_mode 1 reads a video");
      break;
    default:
      need(c.video_path_1, "Video_path_1", "Frame_mode 2 reads two videos");
      need(c.video_path_2, "Video_path_2", "Frame_mode 2 reads two videos");
  }
  if (c.final_image != -1 && c.final_image <= c.initial_image)
    throw InputError("Final_image: " + std::to_string(c.final_image) +
                     " is not after Initial_image " + std::to_string(c.initial_image) +
                     "; expected -1 (to the end) or a position > Initial_image");
  CheckEvaluationConfig(c);
  if (c.side_window == 1) ParseSideWindowRadii(c.side_window_radii);
  if (c.approximate_search == 1 && c.matrix_mode == 1)
    throw InputError("Approximate_search: 1 needs Matrix_mode 2 (bounded) or 0 (auto); "
                     "Matrix_mode is 1 (dense), which compares every pair");
  if (c.matrix_mode == 2 && c.matches_name.empty())
    throw InputError("Matches_name: empty, but Matrix_mode 2 (bounded) keeps only matches; "
                     "expected a .npy or .csv path");
  if (!c.matches_name.empty()) {
    const std::string& m = c.matches_name;
    const auto dot = m.find_last_of('.');
    const std::string ext = dot == std::string::npos ? "" : m.substr(dot);
    if (ext != ".npy" && ext != ".csv")
      throw InputError("Matches_name: " + Quote(m) + " has extension " +
                       (ext.empty() ? std::string("(none)") : ext) + "; expected .npy or .csv");
  }
  if (c.threshold != -1.0 && (c.threshold < 0.0 || c.threshold > 1.0))
    throw InputError("Threshold: " + FormatNumber(c.threshold) +
                     " is not valid; expected -1 (disabled) or a number in [0, 1]");
}

std::vector<int> ParseSideWindowRadii(const std::string& text) {
  auto fail = [&](const std::string& why) {
    throw InputError("Side_window_radii: " + Quote(text) + " is not valid (" + why +
                     "); expected radii in [1, 50] separated by commas, 1 to 16 layers, "
                     "e.g. \"1,2,3\"");
  };
  std::vector<int> radii;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = Trim(item);
    if (item.empty()) fail("empty item");
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (end != item.c_str() + item.size() || errno == ERANGE) fail(Quote(item) + " is not an integer");
    if (v < 1 || v > 50) fail(item + " is out of range");
    radii.push_back(static_cast<int>(v));
  }
  if (!text.empty() && text.back() == ',') fail("empty item");
  if (radii.empty()) fail("no radius");
  if (radii.size() > 16) fail(std::to_string(radii.size()) + " layers");
  return radii;
}

std::string FormatConfig(const Config& c) {
  std::ostringstream os;
  os << "%YAML:1.0\n";
  std::string group;
  for (const auto& b : Bindings()) {
    if (group != b.group) {
      group = b.group;
      os << "\n# --- " << group << " ---\n";
    }
    os << "# " << b.meaning << "\n" << b.key << ": " << ValueText(c, b) << "\n";
  }
  return os.str();
}

std::string ConfigHelpText() {
  const Config defaults;
  std::ostringstream os;
  std::string group;
  for (const auto& b : Bindings()) {
    if (group != b.group) {
      group = b.group;
      os << "\n" << group << ":\n";
    }
    os << "  " << b.key << (b.is_new ? " (new)" : "") << "  [" << RangeText(b)
       << ", default " << ValueText(defaults, b) << "]\n";
    // Wrap the meaning at about 90 columns, indented.
    std::istringstream words(b.meaning);
    std::string word, line = "      ";
    while (words >> word) {
      if (line.size() + word.size() + 1 > 92) {
        os << line << "\n";
        line = "      ";
      }
      line += (line.size() > 6 ? " " : "") + word;
    }
    os << line << "\n";
  }
  return os.str();
}

std::string ConfigMarkdownReference() {
  const Config defaults;
  std::ostringstream os;
  std::string group;
  for (const auto& b : Bindings()) {
    if (group != b.group) {
      group = b.group;
      os << "\n### " << group << "\n\n| key | values | default | meaning |\n|---|---|---|---|\n";
    }
    std::string meaning = b.meaning;
    std::string::size_type pos = 0;
    while ((pos = meaning.find('|', pos)) != std::string::npos) meaning.replace(pos, 1, "\\|"), pos += 2;
    os << "| `" << b.key << "`" << (b.is_new ? " (new)" : "") << " | " << RangeText(b) << " | `"
       << ValueText(defaults, b) << "` | " << meaning << " |\n";
  }
  return os.str();
}

std::string ConfigValueText(const Config& config, const std::string& key) {
  for (const auto& b : Bindings())
    if (key == b.key) return ValueText(config, b);
  throw std::logic_error("ConfigValueText: unknown key " + key);
}

std::vector<std::string> ConfigKeyNames() {
  std::vector<std::string> names;
  for (const auto& b : Bindings()) names.emplace_back(b.key);
  return names;
}

}  // namespace openable
