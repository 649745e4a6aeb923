#include "config/config.h"

#include <stdexcept>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/strings.h"
#include "descriptors/registry.h"
#include "matching/search/engine_registry.h"

namespace openable {
namespace {

// Groups of --help and of docs/configuration.md.
constexpr const char* kDatasets = "Datasets";
constexpr const char* kRepresentation = "Representation";
constexpr const char* kDescription = "Description and matching";
constexpr const char* kRobustness = "Robustness";
constexpr const char* kAuto = "Auto";
constexpr const char* kScale = "Scale";
constexpr const char* kEvaluation = "Evaluation";
constexpr const char* kVerification = "Verification";
constexpr const char* kSnaps = "SNAPS";
constexpr const char* kOdometry = "Odometry";

// The help of Ground_truth_type, from the registry of formats.
const std::string& GroundTruthTypeHelp() {
  static const std::string help = [] {
    std::string text = "Empty: no evaluation. ";
    for (const GroundTruthFormat& f : GroundTruthFormats())
      text +=
          std::string(&f == &GroundTruthFormats().front() ? "" : "; ") + f.name + ": " + f.summary;
    return text +
           ". The run's matrix is evaluated against it with the protocols of "
           "Evaluation_protocol (docs/evaluation.md).";
  }();
  return help;
}

// Evaluation_protocol as Config.txt writes it.
std::string EvaluationProtocolsValue(EvaluationProtocols protocols) {
  return EvaluationProtocolsText(protocols);
}

// Ground_truth_type as Config.txt writes it: empty for no evaluation.
std::string GroundTruthTypeText(GroundTruthType type) {
  return type == GroundTruthType::kNone ? "" : GroundTruthTypeName(type);
}

// The inputs and the matrix outputs (Datasets, Representation).
void AddInputKeys(OptionTable& t, Config& c) {
  // Datasets
  t.AddEnumNumber(
      "Frame_mode", kDatasets, c.input, c.input.frame_mode,
      "Input: 0 image folder(s) (Images_path, optionally Images_path_2), 1 one video "
      "(Video_path_1), 2 two videos matched as one concatenated sequence (Video_path_1, "
      "Video_path_2), 3 a ROS 1 bag (Bag_path, Bag_topic; optionally Bag_topic_2 for a "
      "second traversal).",
      false);
  t.Add("Images_path", kDatasets, c.input, c.input.images_path,
        "Folder of the image sequence (Frame_mode 0). Any file names: frames are taken in natural"
        " order (img2 before img10). PNG, JPEG, TIFF, PGM/PPM, BMP; 8 or 16 bit; grey or colour. "
        "Relative paths are relative to the working directory.",
        false);
  t.Add("Images_path_2", kDatasets, c.input, c.input.images_path_2,
        "Folder of a second traversal of the route (Frame_mode 0). The matrix covers both "
        "sequences concatenated (Images_path first), so its lower-left block holds every frame of"
        " this folder (rows) against every frame of Images_path (columns). Empty: one sequence.");
  t.Add("Descriptors_path", kDatasets, c.input, c.input.descriptors_path,
        "A .npy of one descriptor row per frame of the first traversal, computed elsewhere (a "
        "learned model's features, as VPR_Tutorial and hloc save them): float32 rows are matched "
        "by L2, uint8 rows as bits by Hamming. The frames are not described (Image_descriptor "
        "is not used) but still listed: one row per frame the run reads, in its order. See "
        "docs/descriptors.md, \"Features computed elsewhere\".");
  t.Add("Descriptors_path_2", kDatasets, c.input, c.input.descriptors_path_2,
        "The rows of the second traversal's frames, as Descriptors_path (same width and type); "
        "needed with a second traversal when Descriptors_path is given.");
  t.Add("Images_path_left", kDatasets, c.input, c.input.images_path_left,
        "Left image folder of a stereo camera (Camera_type 1; Images_path is then not used). Same"
        " Images_format and Initial_image/Final_image range as Images_path; the frame names of "
        "the run are the left file names.",
        false);
  t.Add("Images_path_right", kDatasets, c.input, c.input.images_path_right,
        "Right image folder of a stereo camera (Camera_type 1). Must hold as many images as "
        "Images_path_left: pairs are matched by position in natural order.",
        false);
  t.Add("Calibration_path", kDatasets, c.input, c.input.calibration_path,
        "Stereo calibration file (Camera_type 1), OpenCV YAML as the original: ML, MR, DL, DR, R,"
        " T, optional colormap and use_log (docs/cameras.md).",
        false);
  t.Add("Images_format", kDatasets, c.input, c.input.images_format,
        "Extension of the images to take from the folders (e.g. png); empty takes every supported"
        " image file. Unlike the original, names need not be %06d.<ext>.",
        false);
  t.Add("Video_path_1", kDatasets, c.input, c.input.video_path_1,
        "Video file read with OpenCV (Frame_mode 1 and 2).", false);
  t.Add("Video_path_2", kDatasets, c.input, c.input.video_path_2,
        "Second video file (Frame_mode 2), concatenated after Video_path_1.", false);
  t.Add("Bag_path", kDatasets, c.input, c.input.bag_path,
        "ROS 1 bag of Frame_mode 3 (rosbag record; EuRoC, TUM-VI, ...), read with Debian's "
        "rosbag_storage. Frames keep their message header stamps (Ground_truth_type tum and "
        "SNAPS associate by time; Timestamps_name writes them).");
  t.Add("Bag_topic", kDatasets, c.input, c.input.bag_topic,
        "Image topic of Bag_path (sensor_msgs/Image: mono8, mono16, bgr8, rgb8, bgra8, rgba8, "
        "8UC1/3/4, 16UC1; or sensor_msgs/CompressedImage, JPEG or PNG), e.g. /cam0/image_raw; "
        "the left camera's with Camera_type 1.");
  t.Add("Bag_topic_right", kDatasets, c.input, c.input.bag_topic_right,
        "Camera_type 1 with Frame_mode 3: the right camera's image topic; messages are paired "
        "with the left topic's by position, as stereo folders are.");
  t.Add("Bag_path_2", kDatasets, c.input, c.input.bag_path_2,
        "Bag of a second traversal (Frame_mode 3, with Bag_topic_2); empty: Bag_path.");
  t.Add("Bag_topic_2", kDatasets, c.input, c.input.bag_topic_2,
        "Image topic of a second traversal (Frame_mode 3), in Bag_path_2 or else Bag_path: "
        "matched against Bag_topic as Images_path_2 against Images_path. Empty: one traversal.");
  t.Add("Initial_image", kDatasets, c.input, c.input.initial_image, 0, kNoLimit,
        "First frame to process: a 0-based position in the natural order of the folder's images "
        "(or the video's frames). Applies to every folder or video of the run.",
        false);
  t.Add("Final_image", kDatasets, c.input, c.input.final_image, -1, kNoLimit,
        "One past the last frame to process (a position, as Initial_image); -1 processes to the "
        "end.",
        false);
  t.Add("Skip_unreadable", kDatasets, c.input, c.input.skip_unreadable,
        "0 stops at the first frame that cannot be read, naming it; 1 skips such frames with a "
        "warning (the matrix then has fewer rows, and the skipped frames are listed).");
  // Representation
  t.Add("Txt_name", kRepresentation, c.output, c.output.txt_name,
        "Output: the normalised matrix M' (or M'' when Threshold is set, as the original) as "
        "space-separated text, one row per line, with <name>.json beside it (the settings that "
        "shaped it). Empty: not written (text is slow and large for long runs).",
        false);
  t.Add("Npy_name", kRepresentation, c.output, c.output.npy_name,
        "Output: the normalised matrix M' (before any threshold) as a float32 NumPy .npy file "
        "(numpy.load reads it), and beside it <name>.json, the settings that shaped it "
        "(docs/output_formats.md). Empty: not written.");
  t.Add("Timestamps_name", kRepresentation, c.output, c.output.timestamps_name,
        "Output: the time of every frame of the matrix (ROS bags, Frame_mode 3: message header "
        "stamps), one line \"<row> <seconds>\" per row, for tools that associate frames by time "
        "(Snaps_frame_times, TUM trajectories). Empty: not written; refused for frames without "
        "times.");
  t.Add("Png_name", kRepresentation, c.output, c.output.png_name,
        "Output: the normalised matrix M' as a colour PNG image (a .png path), one pixel per "
        "pair of frames, coloured with Matrix_color. Empty: not written.",
        false);
  t.Add("Png_threshold_name", kRepresentation, c.output, c.output.png_threshold_name,
        "Output when Threshold is set: the thresholded matrix M'' as a PNG image, coloured with "
        "Matrix_color at 0 (loop candidate, M' < Threshold) and 1 (not): black and white with map"
        " 0. Empty: Png_name with _thresholded before the extension.");
  t.Add("Matrix_color", kRepresentation, c.output, c.output.matrix_color, 0, 11,
        "Colour map of Png_name, as the original's 12 maps (docs/output_formats.md): 0 grey, 1 "
        "red, 2 green, 3 blue, 4-11 two-colour ramps.",
        false);
  t.Add("Show_images", kRepresentation, c.output, c.output.show_images,
        "1 shows each frame in a window while it is described (needs a display; ignored with a "
        "warning when there is none).",
        false);
}

// Description and matching.
void AddDescriptionKeys(OptionTable& t, Config& c) {
  // Description and matching
  t.AddEnumNumber(
      "Camera_type", kDescription, c.input, c.input.camera_type,
      "0 monocular (ABLE-M); 1 stereo (ABLE-S): pairs of Images_path_left and Images_path_right"
      " are rectified with Calibration_path and matched (SGBM) for D-LDB; other descriptors "
      "describe the rectified left image (docs/cameras.md). 2 panoramic (ABLE-P): each frame is"
      " a 360-degree panorama cut into Panoramas sub-panoramas, compared as Panorama_matching "
      "says.",
      false);
  t.AddEnumNumber(
      "Description_type", kDescription, c.description, c.description.type,
      "0 global: the frame is resized to Patch_size x Patch_size and described at its centre; 1"
      " grid: the frame is cut into Grid_x x Grid_y cells, each resized to Patch_size and "
      "described at its centre, and the descriptors are concatenated.",
      false);
  t.Add("Patch_size", kDescription, c.descriptor, c.descriptor.patch_size, 16, 1024,
        "Side of the square patch in pixels (64 in the ABLE papers). HOG needs a multiple of 8. "
        "Used as given for every descriptor (the original forced 128 for ORB).",
        false);
  t.Add("Grid_x", kDescription, c.description, c.description.grid_x, 1, 64,
        "Grid cells across the frame (Description_type 1).", false);
  t.Add("Grid_y", kDescription, c.description, c.description.grid_y, 1, 64,
        "Grid cells down the frame (Description_type 1).", false);
  t.Add("Panoramas", kDescription, c.description, c.description.panoramas, 1, 64,
        "Sub-panoramas (equal-width vertical strips) of a panoramic frame (Camera_type 2), each "
        "described on its own (global or grid) and concatenated. An even number makes a half-turn"
        " (the route driven the other way) a whole number of strips.",
        false);
  t.AddEnumNumber(
      "Panorama_matching", kDescription, c.matching, c.matching.panorama_matching,
      "Camera_type 2: how two panoramas are compared. 0 aligned (ABLE-P Eq. 2: strip k against "
      "strip k; same-direction revisits only); 1 cross-correlation (Eq. 3, 4: the smallest "
      "distance over every pair of strips; finds revisits in the opposite direction); 2 "
      "circular (the whole panorama turned by the best whole number of strips).");
  t.Add("Illumination_invariance", kDescription, c.preprocess, c.preprocess.illumination_invariance,
        "1 describes the illumination invariant image of Eq. 6, I = log G - Alpha log B - (1 - "
        "Alpha) log R, instead of the grey image. Needs colour frames (an error names the first "
        "grey one).",
        false);
  t.Add("Alpha", kDescription, c.preprocess, c.preprocess.alpha, 0, 1,
        "Alpha of Eq. 6 (0.47 for KITTI's PointGrey Flea2). Replaced by Eq. 7 when Lambda_red, "
        "Lambda_green and Lambda_blue are given.",
        false);
  t.Add("Lambda_red", kDescription, c.preprocess, c.preprocess.lambda_red, 0, 2000,
        "Peak spectral response of the red channel, nm (camera data sheet); with Lambda_green and"
        " Lambda_blue it sets Alpha by Eq. 7. 0 = not given (all three or none).");
  t.Add("Lambda_green", kDescription, c.preprocess, c.preprocess.lambda_green, 0, 2000,
        "Peak spectral response of the green channel, nm; see Lambda_red.");
  t.Add("Lambda_blue", kDescription, c.preprocess, c.preprocess.lambda_blue, 0, 2000,
        "Peak spectral response of the blue channel, nm; see Lambda_red.");
  // The names and their help come from the descriptors' registry.
  static const std::string descriptor_help =
      "Any case: " + DescriptorHelp() +
      ". Several names joined by + or , (HOG+LDB) fuse their matrices (Fusion_weights).";
  t.Add("Image_descriptor", kDescription, c.descriptor, c.descriptor.name, descriptor_help.c_str(),
        false);
  t.Add("Image_sequences", kDescription, c.matching, c.matching.sequence_length, 1, 100000,
        "Sequence length L: the distance of two places sums L single-frame distances along the "
        "diagonal; 1 = single images. Frames with fewer than L predecessors in their traversal: "
        "see Sequence_partial.",
        false);
  t.Add("Threshold", kDescription, c.matching, c.matching.threshold, -1, 1,
        "Theta of Eq. 9: M'' = 0 where M' < Threshold, 1 elsewhere. -1 disables; otherwise in [0,"
        " 1].",
        false);
  t.Add("Ldb_bits", kDescription, c.descriptor, c.descriptor.ldb_bits, 1, 1386,
        "Bits of the LDB descriptor (256 = 32 bytes, as in ABLE-P; 1386 = every test of the 2x2 "
        "to 5x5 grids). See docs/descriptors.md for the selection.");
  t.Add("Sad_patch", kDescription, c.descriptor, c.descriptor.sad_patch, 2, 64,
        "SAD: side in pixels of the squares of the Patch_size x Patch_size/2 thumbnail that are "
        "each normalised to zero mean and unit deviation (8 in SeqSLAM); at most Patch_size/2.");
  t.Add("Model_path", kDescription, c.descriptor, c.descriptor.model_path,
        "Image_descriptor ONNX: the .onnx file of a network whose output is one vector per "
        "image (NetVLAD, CosPlace, MixVPR, EigenPlaces, ...), run by OpenCV's DNN module. Its "
        "rows are floats matched by L2; with Auto 1 it joins the candidates (Image_descriptor "
        "ONNX, sequences of 10, 20 and 40). See docs/descriptors.md, \"Bring your own "
        "descriptor\".");
  t.Add("Model_input_size", kDescription, c.descriptor, c.descriptor.model_input_size,
        "Image_descriptor ONNX: the network's input as WxH pixels (e.g. 224x224); each frame "
        "(each cell of a grid, each sub-panorama) is resized to it.");
  t.Add("Model_channels", kDescription, c.descriptor, c.descriptor.model_channels,
        "Image_descriptor ONNX: the channels the network takes, in order: rgb (torchvision's "
        "models), bgr or grey.");
  t.Add("Model_mean", kDescription, c.descriptor, c.descriptor.model_mean,
        "Image_descriptor ONNX: per channel, subtracted from the pixels scaled to [0, 1] "
        "(comma-separated, or one value for all); ImageNet's by default.");
  t.Add("Model_std", kDescription, c.descriptor, c.descriptor.model_std,
        "Image_descriptor ONNX: per channel, the scaled pixels minus Model_mean are divided by "
        "it (positive; comma-separated, or one value for all); ImageNet's by default.");
  t.Add("Model_normalize", kDescription, c.descriptor, c.descriptor.model_normalize,
        "Image_descriptor ONNX: 1 divides each output row by its L2 norm (as NetVLAD and its "
        "successors are compared); 0 keeps the network's output as it is.");
  t.Add("Model_batch", kDescription, c.descriptor, c.descriptor.model_batch, 1, 1024,
        "Image_descriptor ONNX: images per forward pass (a network exported without a dynamic "
        "batch axis runs one at a time whatever this says).");
  t.Add("Threads", kDescription, c.matching, c.matching.threads, 0, 1024,
        "Worker threads for description and matching; 0 = all cores.");
  t.AddEnumNumber(
      "Sequence_direction", kDescription, c.matching, c.matching.direction,
      "0 sums along diagonals (both routes driven the same way, the original); 1 along anti-"
      "diagonals (the reference route driven the opposite way); 2 the smaller of the two for "
      "every cell (needs a second matrix in dense mode).");
  t.AddEnumName(
      "Sequence_partial", kDescription, c.matching, c.matching.partial,
      "What a sequence cell holds when fewer than L frames precede it in its traversal (the "
      "first L - 1 frames; along anti-diagonals also the last L - 1 references): ahead, the "
      "sum of the L frames that start where its diagonal enters both traversals (the window "
      "looks ahead where it cannot look back, so every cell sums L frames and the first "
      "frames can be matched; a diagonal of fewer than L frames in all has no value); scale, "
      "the terms it has scaled up to L (fewer terms: noisier cells, some become attractors); "
      "skip, no value, the rule of OpenSeqSLAM. A cell without a value is never a candidate "
      "nor a best match, and is written as the largest value of the matrix in Txt_name and "
      "the PNGs and as +inf in Npy_name (docs/matching.md compares the three).");
  t.AddEnumName(
      "Match_score", kDescription, c.matching, c.matching.score.kind,
      "How confident a query's best match is, for Match_threshold, the per-query evaluation "
      "(PR curve, AUC, R@100P, F1), the score column of Matches_name: distance (its "
      "normalised distance) or ratio (its distance over the smallest distance of the query's "
      "other candidates more than Match_score_window frames away: Lowe's ratio test, as "
      "SeqSLAM uses it; 1 without such a rival). docs/evaluation.md defines both.");
  t.Add("Match_score_window", kDescription, c.matching, c.matching.score.window, 0, 100000,
        "Frames on each side of a best match whose cells are not its rivals for the ratio "
        "score (they show the same place); smaller than the reference traversal.");
  t.Add("Match_threshold", kDescription, c.matching, c.matching.match_threshold, -1, 1,
        "A query's best match is accepted when its score (Match_score) is <= this: the report "
        "counts the accepted matches and the evaluation gives their precision and recall (the "
        "overlay marks them). -1: no threshold. Threshold (Eq. 9) still applies to the "
        "matrix.");
  t.Add("Match_consistency", kDescription, c.matching, c.matching.match_consistency, 0, 1000,
        "n: a best match that Match_threshold accepts is accepted only when the best matches "
        "of n other queries confirm it: the nearest query whose sequence shares no frame with "
        "it (at least max(L, 10) frames away, back or else forward), then that query's, each "
        "answer advancing with the queries within +-max(3, gap / 10) frames (docs/evaluation.md"
        "). Checks an answer against independent evidence of the route, as DLoopDetector's "
        "islands do, with no local features. 0: the score alone.");
  t.Add("Contrast_enhancement", kDescription, c.matching, c.matching.contrast.enabled,
        "1 applies SeqSLAM's local contrast enhancement to the single-frame distances, before "
        "sequences: each cell minus the mean of its row's cells within +-Contrast_window "
        "references of its traversal, over their standard deviation (0 where they are all "
        "equal), then the matrix shifted so that its smallest value is 0. Any descriptor; "
        "dense matrices only.");
  t.Add("Contrast_window", kDescription, c.matching, c.matching.contrast.window, 1, 100000,
        "References on each side of a cell that give its local mean and deviation "
        "(Contrast_enhancement).");
  t.Add("Fusion_weights", kDescription, c.matching, c.matching.fusion_weights,
        "Image_descriptor lists several descriptors (HOG+LDB): the weight of each one's "
        "single-frame matrix, first divided by its largest value, comma-separated in the order "
        "of the names (\"1,0.5\"); empty: equal weights, which fusing descriptors of different "
        "distances (Hamming, L2, L1) does not allow. Dense matrices only.");
}

// Robustness studies and the auto mode.
void AddRobustnessAndAutoKeys(OptionTable& t, Config& c) {
  // Robustness
  t.Add("Side_window", kRobustness, c.preprocess, c.preprocess.side_window,
        "1 applies side-window multilayer pixel fusion to the grey image before description "
        "(Algorithm 1 of the side-window direct SLAM paper): in every layer each pixel becomes "
        "the mean of the one of its eight side windows (U, D, L, R, NW, NE, SW, SE) closest to "
        "it, which smooths noise but keeps edges. 0 = off. See docs/descriptors.md.");
  t.Add("Side_window_radii", kRobustness, c.preprocess, c.preprocess.side_window_radii,
        "Radius of each side-window layer, in order, comma-separated (\"1,2,3\": three layers, "
        "windows of 2x3 to 4x7 pixels); integers in [1, 50], 1 to 16 layers. Used when "
        "Side_window is 1.");
  t.Add("Noise_gaussian", kRobustness, c.preprocess, c.preprocess.noise.gaussian, 0, 1,
        "Robustness studies: variance of the Gaussian noise added to every frame's intensities in"
        " [0, 1] (per channel, then clipped to [0, 1]) before grey conversion; the side-window "
        "paper uses 0.003. 0 = off.");
  t.Add("Noise_salt_pepper", kRobustness, c.preprocess, c.preprocess.noise.salt_pepper, 0, 1,
        "Robustness studies: fraction of the pixels of every frame set to black or white (even "
        "odds), after the Gaussian noise; the side-window paper uses 0.1. 0 = off.");
  t.Add("Noise_overexposure", kRobustness, c.preprocess, c.preprocess.noise.overexposure, 0,
        kNoLimit,
        "Robustness studies: overexposure of every frame, intensities v in [0, 1] multiplied by 1"
        " + this value and saturated at 1 (1 doubles the exposure: everything above 0.5 becomes "
        "white). Applied first. 0 = off.");
  t.Add("Noise_seed", kRobustness, c.preprocess, c.preprocess.noise.seed, 0, 1000000000,
        "Seed of the noise: each frame's noise depends only on this seed, its traversal and its "
        "index, so a run is repeatable whatever the number of Threads.");
  // Auto
  t.Add("Auto", kAuto, c.automatic, c.automatic.enabled,
        "1 chooses the description and matching settings from the data, without ground truth "
        "(config/presets/auto.txt; two traversals: Images_path and Images_path_2): every frame "
        "is described once per candidate descriptor, each candidate of Auto_candidates gets its "
        "query-reference matrix, and the one with the highest agreement (docs/evaluation.md: "
        "consistency of the best matches of independent queries, distinctiveness to break "
        "ties) is run as if its settings were written here. When its consistency is below "
        "Auto_min_consistency the run still writes its outputs but says it is unreliable and "
        "accepts no match.");
  t.Add("Auto_candidates", kAuto, c.automatic, c.automatic.candidates,
        "The settings Auto tries: groups separated by |, each the combinations of its axes "
        "Key=v1,v2 separated by spaces (values as openable_sweep --vary takes them). Keys of "
        "the Description and matching and Robustness groups that change the matrix; a fused "
        "descriptor without Fusion_weights gets equal weights. The default was measured on "
        "Nordland, Gardens Point, the RTAB-Map sample and night-like variants "
        "(docs/benchmarks.md).");
  t.Add("Auto_min_consistency", kAuto, c.automatic, c.automatic.min_consistency, 0, 1,
        "The chosen setting is trusted when at least this share of its best matches agree with "
        "the best match of an independent query (consistency); below, the run is reported "
        "unreliable and accepts no match. Unrelated traversals reach at most 0.19 in the "
        "measurements, two traversals of a route where the best setting finds the places 0.6 "
        "and more.");
}

// Scale: dense or bounded matrices, approximate search, the descriptor cache.
void AddScaleKeys(OptionTable& t, Config& c) {
  // Scale
  t.AddEnumNumber(
      "Matrix_mode", kScale, c.scale, c.scale.matrix_mode,
      "0 auto: dense when the N x N matrix fits in Memory_limit, bounded otherwise (the run "
      "says which and why); 1 dense: the whole matrix, every output; 2 bounded: the matrix is "
      "never held: rows are computed in ranges and only the matches of Best_matches and "
      "Band_width are kept (Matches_name); with two traversals only queries (Images_path_2) "
      "against references "
      "(Images_path) are computed.");
  t.Add("Memory_limit", kScale, c.scale, c.scale.memory_limit, 0, kNoLimit,
        "GiB the dense matrices may take before auto mode switches to bounded; 0 = three quarters"
        " of the machine's memory.");
  t.Add("Best_matches", kScale, c.scale, c.scale.keep.best, 0, 100000,
        "k: the k smallest distances of every query are kept in Matches_name (one sequence: among"
        " frames at least Exclusion frames earlier). 0 keeps none.");
  t.Add("Band_width", kScale, c.scale, c.scale.keep.band, -1, kNoLimit,
        "Also keep every cell with |i - j| <= Band_width, frames counted from the start of each "
        "traversal (aligned traversals); -1 keeps no band.");
  t.Add("Matches_name", kScale, c.scale, c.scale.matches_name,
        "Kept matches: .npy (structured: query, reference int32; distance float32 = M'; rank "
        "int32, 1 = best, 0 = band only) or .csv. Frame numbers count from the start of their "
        "traversal. Required in bounded mode; optional in dense mode (taken from the matrix).");
  t.Add("Approximate_search", kScale, c.scale, c.scale.approximate_search,
        "1: bounded mode finds the Best_matches candidates of each query with the index of "
        "Approximate_engine instead of comparing every pair, then scores them with the sequence "
        "sum; faster on very large runs, recall below 1 (docs/benchmarks.md). No band.");
  // The approximate search's keys: bound onto ApproximateOptions (ScaleOptions::approximate),
  // the engine names and their meanings from its registry (matching/search/engine_registry.h), the
  // ranges from ApproximateOptions.
  ApproximateOptions& approximate = c.scale.approximate;
  using A = ApproximateOptions;
  t.AddName("Approximate_engine", kScale, c.scale, approximate.engine, &ParseApproximateEngine,
            "Index of Approximate_search (docs/matching.md): " + ApproximateEngineHelp());
  t.Add("Approximate_checks", kScale, c.scale, approximate.checks, A::kChecksRange.min,
        A::kChecksRange.max,
        "Approximate_engine flann, k-d trees (vector descriptors): references examined per "
        "query (more: better recall, slower; LSH for binary descriptors ignores it).");
  t.Add("Approximate_ef_search", kScale, c.scale, approximate.ef_search, A::kEfSearchRange.min,
        A::kEfSearchRange.max,
        "Approximate_engine hnsw: length of the candidate list while searching the graph "
        "(efSearch; raised to Best_matches when smaller). More: better recall, slower.");
  t.Add("Approximate_nprobe", kScale, c.scale, approximate.nprobe, A::kNprobeRange.min,
        A::kNprobeRange.max,
        "Approximate_engine ivf and binary_ivf: cells scanned per query (nprobe; the index has "
        "about 2 sqrt(N) cells for N references). More: better recall, slower.");
  t.Add("Descriptor_cache", kScale, c.scale, c.scale.descriptor_cache,
        "Folder of the descriptor cache; empty = off. Each frame's descriptor row is kept under a"
        " hash of the image file's bytes and of every setting that changes the row "
        "(docs/output_formats.md), so a run interrupted or repeated with the same description "
        "settings describes only the frames not cached, and gives the same matrix bit for bit. "
        "Image folders only (not videos or stereo pairs). Created when missing.");
}

// Evaluation and verification.
void AddEvaluationKeys(OptionTable& t, Config& c) {
  // Evaluation
  t.AddEnumName("Ground_truth_type", kEvaluation, c.evaluation, c.evaluation.truth.type,
                &ParseGroundTruthType, &GroundTruthTypeText, GroundTruthTypeHelp().c_str());
  t.Add("Ground_truth", kEvaluation, c.evaluation, c.evaluation.truth.path,
        "Ground-truth file (not needed for aligned). Pairs and poses count frames from the start "
        "of the source, as Initial_image does; for poses of two traversals, the poses of the "
        "reference (Images_path).");
  t.Add("Ground_truth_2", kEvaluation, c.evaluation, c.evaluation.truth.path_2,
        "Poses of the query traversal (Images_path_2 or Video_path_2) for kitti, tum and "
        "positions ground truth of two traversals.");
  t.Add("Ground_truth_soft", kEvaluation, c.evaluation, c.evaluation.truth.soft_path,
        "vpr_tutorial: VPR_Tutorial's GTsoft (.npy, database x queries): cells outside GThard "
        "that VPR_Tutorial's protocol counts neither right nor wrong. Empty: the GTsoft of a "
        "Ground_truth .npz, or none.");
  t.Add("Ground_truth_base", kEvaluation, c.evaluation, c.evaluation.truth.base, -1, 1,
        "Pairs: 0 or 1 for 0- or 1-based frame numbers; -1 reads a comment line saying "
        "\"0-based\" or \"1-based\", else 0.");
  t.Add("Ground_truth_radius", kEvaluation, c.evaluation, c.evaluation.truth.radius, 0, kNoLimit,
        "Poses: two frames are the same place when their positions are closer than this (the "
        "poses' unit, metres for KITTI).",
        true, /*min_excluded=*/true);
  t.Add("Ground_truth_heading", kEvaluation, c.evaluation, c.evaluation.truth.heading_limit, -1,
        180,
        "Poses: and when their viewing directions differ by less than this many degrees (a "
        "forward camera cannot recognise a place seen the other way); -1: no limit.");
  t.Add("Ground_truth_min_gap", kEvaluation, c.evaluation, c.evaluation.min_frame_gap, -1, kNoLimit,
        "Poses, one sequence: only frames at least this many frames apart are loops; -1: "
        "Exclusion.");
  t.Add("Ground_truth_time_tolerance", kEvaluation, c.evaluation, c.evaluation.truth.time_tolerance,
        0, kNoLimit,
        "tum with frames that carry times (Frame_mode 3, ROS bags): each frame takes the pose "
        "of the file with the nearest timestamp, which must be within this many seconds (else "
        "the frame is named in an error). Frames without times take pose line i as frame i.");
  t.Add("Ground_truth_axes", kEvaluation, c.evaluation, c.evaluation.truth.axes,
        "Poses: axes of the distance and heading: xyz (3D), xz (the ground plane of KITTI's "
        "camera frame, y down) or xy.");
  t.Add("Tolerance", kEvaluation, c.evaluation, c.evaluation.protocol.tolerance, 0, kNoLimit,
        "Frames: a best match within this many frames of a true match is correct (2 for Nordland "
        "and Gardens Point, 3 for KITTI in docs/benchmarks.md).");
  t.Add("Exclusion", kEvaluation, c.evaluation, c.evaluation.protocol.exclusion, 1, kNoLimit,
        "One sequence: the candidates of frame q are frames at least this many frames earlier "
        "(recent frames always look alike and are not loops).");
  t.Add("Vicinity", kEvaluation, c.evaluation, c.evaluation.protocol.vicinity, 0, kNoLimit,
        "ABLE-P protocol: a detected cell is a true positive when a ground-truth loop lies within"
        " this many frames of it in both directions (7 in the ABLE-P paper).");
  // The protocols and their help come from their table (evaluation/protocols.h).
  static const std::string protocol_help =
      "Protocols reported: " + EvaluationProtocolsHelp() +
      ", several joined by commas, or all. Each computes its figures as that code does "
      "(docs/evaluation.md); Tolerance widens every ground truth.";
  t.AddEnumName("Evaluation_protocol", kEvaluation, c.evaluation, c.evaluation.protocol.protocols,
                &ParseEvaluationProtocols, &EvaluationProtocolsValue, protocol_help.c_str());
  t.Add("Evaluation_name", kEvaluation, c.evaluation, c.evaluation.name,
        "Output prefix of the evaluation: <name>.json (figures and settings), "
        "<name>_per_query.csv and <name>_ablep.csv (curves), <name>_pr.png (precision-recall "
        "figure), <name>_overlay.png (ground truth and best matches over the matrix). Empty: the "
        "figures are printed only.");
  t.Add("Evaluation_label", kEvaluation, c.evaluation, c.evaluation.label,
        "Name of this run in the figure's legend and the JSON; empty: descriptor and L, e.g. "
        "\"LDB L=10\".");
  t.Add("Report_name", kEvaluation, c.evaluation, c.evaluation.report_name,
        "A self-contained HTML page of the run (images embedded, opens offline in any "
        "browser). With Ground_truth_type: the settings, the figures, the precision-recall "
        "figure, the matrix with the ground truth, an explorer, and the frames of the most "
        "confident wrong matches and of the misses side by side. Without: the settings, the "
        "operating point (best matches answered, accepted, confirmed), the matrix, the explorer "
        "and the frames of the most and least confident accepted matches, to check by eye "
        "(docs/output_formats.md). Not written in bounded mode. Empty: no report.");
  t.Add("Report_examples", kEvaluation, c.evaluation, c.evaluation.report_examples, 0, 100,
        "How many frames of each kind the report shows: with ground truth the most confident "
        "wrong matches and the misses, without it the most and the least confident accepted "
        "matches (0: none).");
  // Verification
  t.Add("Verification", kVerification, c.verification, c.verification.enabled,
        "1: check each query's Verification_candidates best candidates geometrically (local "
        "features, ratio test, RANSAC fundamental or essential matrix, homography fallback) and "
        "by temporal consistency; the run's answer for a query is its best-ranked verified "
        "candidate, and a query without one has no answer (docs/verification.md). The frames "
        "of the candidates are read again: image folders and stereo pairs, not videos.");
  t.AddEnumName("Verification_features", kVerification, c.verification, c.verification.features,
                "Local features of the verification: ORB (binary, fast) or SIFT (slower, more "
                "matches across seasons and light); OpenCV's implementations.");
  t.Add("Verification_max_features", kVerification, c.verification, c.verification.max_features, 10,
        100000, "Features kept per frame (the strongest).");
  t.Add("Verification_ratio", kVerification, c.verification, c.verification.ratio, 0.1, 1,
        "Lowe's ratio test: a feature match is kept when its distance is below this fraction of"
        " the second nearest's.");
  t.Add("Verification_min_inliers", kVerification, c.verification, c.verification.min_inliers, 5,
        100000, "A candidate is verified when its geometric model has at least this many inliers.");
  t.Add("Verification_ransac_threshold", kVerification, c.verification,
        c.verification.ransac_threshold, 0.1, 100,
        "RANSAC: pixels between a point and its epipolar line (or its homography image) for "
        "the point to be an inlier.");
  t.Add("Verification_candidates", kVerification, c.verification, c.verification.candidates, 1, 100,
        "k: candidates checked per query, the k best at distinct places (each more than "
        "Match_score_window frames from the others), in order of distance.");
  t.Add("Verification_consistency", kVerification, c.verification, c.verification.consistency, 0,
        kNoLimit,
        "n: a verified candidate is accepted only when the n previous queries also had verified "
        "candidates at references within Tolerance frames of it (DLoopDetector's temporal "
        "consistency); 0: off.");
  t.Add("Verification_calibration", kVerification, c.verification, c.verification.calibration,
        "Camera intrinsics of the frames: a KITTI calib.txt (P0) or an OpenCV YAML stereo "
        "calibration (ML). Given: the essential matrix is estimated instead of the fundamental "
        "matrix. Empty: uncalibrated.");
  t.Add("Verification_calibration_scale", kVerification, c.verification,
        c.verification.calibration_scale, 0.01, 10,
        "Multiplies the calibration's focal lengths and principal point (0.5 for frames at half "
        "the calibrated size).");
  t.Add("Verification_cache", kVerification, c.verification, c.verification.cache_mb, 1, kNoLimit,
        "MB of frame features kept in memory; beyond, the least recently used are dropped and "
        "computed again when needed (the report counts it).");
  t.Add("Loops_name", kVerification, c.output, c.output.loops_name,
        "Verification: CSV of every candidate checked (query, reference, rank, distance, score, "
        "matches, inliers, model, geometric, streak, verified); frame numbers count from the "
        "start of their traversal. Empty: not written.");
}

// The SNAPS add-on.
void AddSnapsKeys(OptionTable& t, Config& c) {
  // SNAPS
  t.Add("Snaps_trajectory", kSnaps, c.snaps, c.snaps.trajectory,
        "openable_snaps: the drifting trajectory to correct (visual odometry), in "
        "Snaps_trajectory_format.");
  t.AddEnumName(
      "Snaps_odometry", kSnaps, c.odometry, c.odometry.kind,
      "Empty: read Snaps_trajectory. mono: compute it from the images (Snaps_images or "
      "Images_path) with the monocular odometry (docs/odometry.md; the scale comes from "
      "Odometry_scale); stereo: from Images_path_left and Images_path_right (rectified with "
      "Calibration_path, or already rectified with Odometry_calibration). The computed "
      "trajectory is written as <Snaps_output_name>_odometry.txt (KITTI format).");
  t.AddEnumName(
      "Snaps_trajectory_format", kSnaps, c.snaps, c.snaps.trajectory_format,
      "kitti (12 numbers per line, pose i = frame i), kitti-id (frame number + 12 numbers: "
      "keyframes) or tum (timestamp tx ty tz qx qy qz qw). The corrected trajectories are "
      "written in the same format.");
  t.Add("Snaps_world_to_camera", kSnaps, c.snaps, c.snaps.world_to_camera,
        "1: the trajectory file holds world-to-camera matrices (SO-DSO's poses_history_file.txt);"
        " they are inverted on reading and again on writing.");
  t.Add("Snaps_ground_truth", kSnaps, c.snaps, c.snaps.ground_truth,
        "Ground-truth trajectory (camera-to-world) for the error figures and the plot; empty: no "
        "evaluation. Associated by frame number (kitti, kitti-id) or timestamp (tum).");
  t.AddEnumName("Snaps_ground_truth_format", kSnaps, c.snaps, c.snaps.ground_truth_format,
                "Format of Snaps_ground_truth: kitti, kitti-id or tum.");
  t.Add("Snaps_time_tolerance", kSnaps, c.snaps, c.snaps.time_tolerance, 0, kNoLimit,
        "tum: a pose and its ground truth are associated when their timestamps differ by at most "
        "this many seconds.");
  t.AddEnumName(
      "Snaps_loops", kSnaps, c.snaps, c.snaps.loops,
      "Where the loops come from: search (SNAPS's own search on thumbnails of Snaps_images, run"
      " online with the discounted update, as the paper), openable (an OpenABLE run on the same"
      " images with the description keys of this file: each frame's best match at least "
      "Snaps_frame_distance frames back, kept below Snaps_matrix_threshold; with Verification 1"
      " its verified answers instead, docs/verification.md), pairs "
      "(Snaps_loops_file: two frame numbers per line, read as Ground_truth_type pairs), matrix "
      "(Snaps_loops_file: the normalised matrix of an OpenABLE run of one sequence, "
      ".npy/.txt/image: each frame's best match at least Snaps_frame_distance frames back, kept"
      " below Snaps_matrix_threshold).");
  t.Add("Snaps_loops_file", kSnaps, c.snaps, c.snaps.loops_file,
        "Pairs file (Snaps_loops pairs) or saved matrix (Snaps_loops matrix).");
  t.Add("Snaps_frame_times", kSnaps, c.snaps, c.snaps.frame_times,
        "Snaps_loops matrix: the time of each matrix row, as Timestamps_name wrote it for a run "
        "of a ROS bag; with a TUM trajectory, each row takes the pose nearest in time (within "
        "Snaps_time_tolerance) instead of pose i for frame i. Snaps_loops openable on a bag "
        "(Frame_mode 3) does the same by itself. Empty: by frame number.");
  t.Add("Snaps_keyframe_tolerance", kSnaps, c.snaps, c.snaps.keyframe_tolerance, 0, kNoLimit,
        "Snaps_loops pairs and matrix: a frame that is not a pose of the trajectory (keyframes) "
        "takes the nearest pose within this many frames; 0 keeps only frames that are poses.");
  t.Add("Snaps_drop_outside", kSnaps, c.snaps, c.snaps.drop_outside,
        "Snaps_loops pairs: 0 stops at a pair with a frame outside the trajectory's frames (an "
        "error naming the line); 1 drops such pairs and says how many (a ground-truth list of a "
        "whole sequence against a trajectory that stops a few frames early).");
  t.Add("Snaps_middle_of_runs", kSnaps, c.snaps, c.snaps.middle_of_runs,
        "Snaps_loops pairs: 1 keeps, of each query's references, only the middle of each run of "
        "consecutive frames (ground-truth lists pair a query with every frame within a radius; "
        "the middle is the nearest place); 0 keeps every pair.");
  t.Add("Snaps_matrix_threshold", kSnaps, c.snaps, c.snaps.matrix_threshold, 0, 1,
        "Snaps_loops matrix: a best match is a loop when its normalised distance M' is below "
        "this; its similarity Q is 1 - M'.");
  t.Add("Snaps_images", kSnaps, c.snaps, c.snaps.images,
        "Snaps_loops search: image folder of the trajectory's frames (image i in natural order is"
        " frame i); empty: Images_path.");
  t.Add("Snaps_thumbnail_scale", kSnaps, c.snaps, c.snaps.search.thumbnail_scale, 0.01, 1,
        "Thumbnails are the frames scaled by this (1/6 in the paper).");
  t.Add("Snaps_window", kSnaps, c.snaps, c.snaps.search.window, 2, 64,
        "B: side of the sliding window of the universal image quality index (Eq. 4, 5); the paper"
        " gives none, 8 is Wang and Bovik's.");
  t.Add("Snaps_min_similarity", kSnaps, c.snaps, c.snaps.search.min_similarity, -1, 1,
        "Minimum similarity Q of a loop (0.75 in the paper).");
  t.Add("Snaps_yaw_limit", kSnaps, c.snaps, c.snaps.search.max_yaw_difference_deg, 0, 180,
        "Candidates whose heading differs from the current frame's by more than this many degrees"
        " are ignored (10 in the paper).");
  t.Add("Snaps_radius", kSnaps, c.snaps, c.snaps.search.radius, 0, kNoLimit,
        "Candidates lie within this many metres of the current (corrected) position (not given in"
        " the paper).");
  t.Add("Snaps_frame_distance", kSnaps, c.snaps, c.snaps.search.frame_distance, 1, kNoLimit,
        "M: the last M frames are never candidates (frame numbers of the trajectory's poses; not "
        "given in the paper).");
  t.Add("Snaps_attempts", kSnaps, c.snaps, c.snaps.search.attempts, 1, kNoLimit,
        "At most this many candidates, nearest first, are compared (not given in the paper).");
  t.Add("Snaps_discount_length", kSnaps, c.snaps, c.snaps.search.discount.discount_length, 0,
        kNoLimit,
        "K of Eq. 6: the last K poses move towards the reference (not given in the paper; gamma "
        "is 0 beyond 300 poses for the first loop).");
  t.Add("Snaps_pause", kSnaps, c.snaps, c.snaps.search.discount.pause, 0, kNoLimit,
        "Inter-frame pause: no loop is closed within this many poses after the last one (not "
        "given in the paper).");
  t.AddEnumName(
      "Snaps_corrector", kSnaps, c.snaps, c.snaps.corrector,
      "discounted (the paper's Eq. 6), pose-graph (least squares over odometry and loop edges) "
      "or both.");
  t.Add("Snaps_loop_weight", kSnaps, c.snaps, c.snaps.pose_graph.loop_weight, 0, kNoLimit,
        "Pose graph: information of a loop edge's position residual, 1/m^2 (1 = sigma 1 m).", true,
        /*min_excluded=*/true);
  t.Add("Snaps_odometry_translation_weight", kSnaps, c.snaps,
        c.snaps.pose_graph.odometry_translation_weight, 0, kNoLimit,
        "Pose graph: information of an odometry edge's translation per pose step, 1/m^2 (2500 = "
        "sigma 0.02 m).",
        true, /*min_excluded=*/true);
  t.Add("Snaps_odometry_rotation_weight", kSnaps, c.snaps,
        c.snaps.pose_graph.odometry_rotation_weight, 0, kNoLimit,
        "Pose graph: information of an odometry edge's rotation per pose step, 1/rad^2 (1e6 = "
        "sigma 0.001 rad).",
        true, /*min_excluded=*/true);
  t.AddEnumName(
      "Snaps_robust_kernel", kSnaps, c.snaps, c.snaps.pose_graph.robust_kernel,
      "Pose graph: robust kernel on loop edges, none, huber or cauchy (a few wrong loops then "
      "pull with a bounded force).");
  t.Add("Snaps_robust_scale", kSnaps, c.snaps, c.snaps.pose_graph.robust_scale, 0, kNoLimit,
        "Pose graph: scale of the robust kernel in sigmas of a loop edge.", true,
        /*min_excluded=*/true);
  t.AddEnumName("Snaps_axes", kSnaps, c.snaps, c.snaps.axes,
                "Ground plane of the plot and of the yaw: xz (KITTI: y points down) or xy (z up).");
  t.Add("Snaps_output_name", kSnaps, c.snaps, c.snaps.output_name,
        "Output prefix: <name>_discounted.txt and/or <name>_pose_graph.txt (the corrected "
        "trajectories), <name>_loops.csv, <name>.json (figures), <name>.png (plot). Empty: "
        "figures printed only.");
}

// The odometry of the SNAPS chain.
void AddOdometryKeys(OptionTable& t, Config& c) {
  // Odometry
  t.Add("Odometry_calibration", kOdometry, c.odometry, c.odometry.calibration,
        "KITTI calib.txt (P0, P1 lines) of rectified images: the intrinsics (P0) and, for stereo,"
        " the baseline (P1). Stereo may use Calibration_path instead (raw pairs, rectified here).");
  t.Add("Odometry_calibration_scale", kOdometry, c.odometry, c.odometry.calibration_scale, 0.01, 10,
        "Multiplies the focal lengths and principal point of Odometry_calibration (0.5 for images"
        " at half the calibrated size, as the shared KITTI frames).");
  t.AddEnumName(
      "Odometry_scale", kOdometry, c.odometry, c.odometry.scale,
      "mono: where the length of each step comes from, since one camera cannot measure it: "
      "truth (the step lengths of Snaps_ground_truth), step (Odometry_step_length every frame) "
      "or none (unit steps: the trajectory's scale is arbitrary).");
  t.Add("Odometry_step_length", kOdometry, c.odometry, c.odometry.step_length, 0, kNoLimit,
        "mono with Odometry_scale step: metres travelled between two frames (speed / frame rate).");
  t.Add("Odometry_features", kOdometry, c.odometry, c.odometry.features,
        "ORB or SIFT; empty: SIFT (the paper's; also the better one for the monocular odometry on"
        " KITTI, docs/odometry.md).");
  t.Add("Odometry_max_features", kOdometry, c.odometry, c.odometry.max_features, 10, kNoLimit,
        "Features detected per frame.");
  t.Add("Odometry_ratio_test", kOdometry, c.odometry, c.odometry.ratio_test, 0.1, 1,
        "Lowe's ratio test on the two nearest descriptors.");
  t.Add("Odometry_ransac_threshold", kOdometry, c.odometry, c.odometry.ransac_threshold, 0, 100,
        "RANSAC inlier threshold, pixels (mono: distance to the epipolar line, default 0.5; "
        "stereo: PnP reprojection error, default 2); 0 keeps the default.");
  t.Add("Odometry_min_inliers", kOdometry, c.odometry, c.odometry.min_inliers, 0, kNoLimit,
        "Fewer inliers: the step keeps the previous motion (constant velocity) and is counted as "
        "failed in the report (default 20 mono, 15 stereo; 0 keeps the default).");
  t.Add("Odometry_matcher", kOdometry, c.odometry, c.odometry.matcher,
        "stereo: disparity by sgbm or bm (block matching, as the paper).");
  t.Add("Odometry_wls_filter", kOdometry, c.odometry, c.odometry.wls_filter,
        "stereo: 1 filters the disparity with the weighted-least-squares filter (the paper).");
  t.Add("Odometry_num_disparities", kOdometry, c.odometry, c.odometry.num_disparities, 16, 256,
        "stereo: disparity search range, pixels (a multiple of 16, at most 256: the stereo "
        "odometry's limit).");
  t.Add("Odometry_max_depth", kOdometry, c.odometry, c.odometry.max_depth, 1, kNoLimit,
        "stereo: points farther than this many metres are not used in PnP.");
}

}  // namespace

OptionTable ConfigTable(Config& c) {
  OptionTable t;
  AddInputKeys(t, c);
  AddDescriptionKeys(t, c);
  AddRobustnessAndAutoKeys(t, c);
  AddScaleKeys(t, c);
  AddEvaluationKeys(t, c);
  AddSnapsKeys(t, c);
  AddOdometryKeys(t, c);
  return t;
}

bool Config::operator==(const Config& other) const {
  Config a = *this, b = other;
  const OptionTable ta = ConfigTable(a), tb = ConfigTable(b);
  for (std::size_t i = 0; i < ta.Bindings().size(); ++i)
    if (ta.Bindings()[i].format() != tb.Bindings()[i].format()) return false;
  return true;
}

Config ParseConfigText(const std::string& text, const std::string& name) {
  Config config;
  ParseOptionText(ConfigTable(config), text, name);
  return config;
}

Config LoadConfig(const std::string& path) { return LoadConfig(path, Config()); }

Config LoadConfig(const std::string& path, Config base) {
  const std::string text =
      ReadInputFile(path, "configuration file " + Quoted(path),
                    "expected a readable Config.txt; see Test_OpenABLE --help");
  ParseOptionText(ConfigTable(base), text, path);
  return base;
}

void ApplyOverride(Config& config, const std::string& assignment, const std::string& where) {
  ApplyOptionOverride(ConfigTable(config), assignment, where);
}

void CheckEvaluationConfig(const Config& c) { c.evaluation.Check(); }

void CheckConfig(const Config& c) {
  c.descriptor.Check();
  c.description.Check();
  c.preprocess.Check();
  const CameraType camera = c.input.camera_type;
  for (const std::string& name : DescriptorList(c.descriptor.name))
    if (name == "D-LDB" && camera != CameraType::kStereo)
      throw InputError("Image_descriptor: D-LDB needs Camera_type 1 (stereo); Camera_type is " +
                       std::to_string(static_cast<int>(camera)));
  c.input.Check();
  if (camera == CameraType::kStereo && c.preprocess.illumination_invariance)
    throw InputError(
        "Illumination_invariance: 1 with Camera_type 1 (stereo); expected 0: the "
        "stereo pipeline describes grey rectified images, and Eq. 6 needs colour");
  c.output.Check();
  if (!c.output.timestamps_name.empty() && c.input.frame_mode != FrameMode::kBag)
    throw InputError("Timestamps_name: " + Quoted(c.output.timestamps_name) + " with Frame_mode " +
                     std::to_string(static_cast<int>(c.input.frame_mode)) +
                     "; expected Frame_mode 3 (ROS bags: the only frames that carry times), or "
                     "Timestamps_name empty");
  c.matching.Check();
  c.automatic.Check();
  c.scale.Check();
  CheckEvaluationConfig(c);
}

void CheckSnapsConfig(const Config& c) {
  using odometry::OdometryKind;
  using snaps::LoopSource;
  c.snaps.Check();
  const OdometryKind kind = c.odometry.kind;
  if (kind == OdometryKind::kNone && c.snaps.trajectory.empty())
    throw InputError(
        "Snaps_trajectory: empty; expected the path of the trajectory to correct "
        "(or Snaps_odometry mono or stereo to compute it from the images)");
  if (kind != OdometryKind::kNone) {
    c.odometry.Check();
    if (kind == OdometryKind::kMono && c.odometry.calibration.empty())
      throw InputError(
          "Odometry_calibration: empty; expected the camera's KITTI calib.txt "
          "for Snaps_odometry mono");
    if (kind == OdometryKind::kMono && c.odometry.scale == odometry::StepScale::kTruth &&
        c.snaps.ground_truth.empty())
      throw InputError(
          "Odometry_scale: truth needs Snaps_ground_truth (its step lengths give "
          "the scale); expected a ground truth, or Odometry_scale step or none");
    if (kind == OdometryKind::kMono && c.snaps.images.empty() && c.input.images_path.empty())
      throw InputError(
          "Snaps_images: empty and Images_path empty; expected the image folder "
          "of the monocular odometry");
    if (kind == OdometryKind::kStereo) {
      if (c.input.images_path_left.empty() || c.input.images_path_right.empty())
        throw InputError(
            "Images_path_left, Images_path_right: expected both folders for "
            "Snaps_odometry stereo");
      if (c.input.calibration_path.empty() && c.odometry.calibration.empty())
        throw InputError(
            "Calibration_path, Odometry_calibration: both empty; expected the "
            "stereo calibration (Calibration.txt for raw pairs, or KITTI calib.txt "
            "for rectified pairs)");
    }
  }
  const LoopSource loops = c.snaps.loops;
  const std::string source = EnumName(loops);
  if ((loops == LoopSource::kPairs || loops == LoopSource::kMatrix) && c.snaps.loops_file.empty())
    throw InputError("Snaps_loops_file: empty; expected the " +
                     std::string(loops == LoopSource::kPairs ? "pairs file" : "saved matrix") +
                     " that Snaps_loops " + source + " reads");
  if ((loops == LoopSource::kSearch || loops == LoopSource::kOpenable) && c.snaps.images.empty() &&
      c.input.images_path.empty() &&
      !(kind == OdometryKind::kStereo && !c.input.images_path_left.empty()))
    throw InputError(
        "Snaps_images: empty and Images_path empty; expected the image folder "
        "of the trajectory's frames for Snaps_loops " +
        source);
}

std::string FormatConfig(const Config& config) {
  Config copy = config;
  return FormatOptionText(ConfigTable(copy));
}

std::string ConfigHelpText(const std::string& group) {
  Config defaults;
  const OptionTable table = ConfigTable(defaults);
  if (group.empty()) return OptionHelpText(table);
  // A group by its name or its first word, in any case ("description" for "Description and
  // matching").
  const std::vector<std::string> groups = OptionGroups(table);
  std::string names;
  for (const std::string& g : groups) {
    const std::string name = Lower(g);
    if (name == Lower(group) || name.substr(0, name.find(' ')) == Lower(group))
      return OptionHelpText(table, g);
    names += (names.empty() ? "" : ", ") + g;
  }
  throw InputError("--help-keys: no group " + Quoted(group) + "; expected one of " + names +
                   " (or none: every key)");
}

std::vector<std::string> ConfigGroupNames() {
  Config defaults;
  return OptionGroups(ConfigTable(defaults));
}

std::string ConfigMarkdownReference() {
  Config defaults;
  return OptionMarkdown(ConfigTable(defaults));
}

std::string ConfigValueText(const Config& config, const std::string& key) {
  Config copy = config;
  const OptionTable table = ConfigTable(copy);
  if (const OptionBinding* b = table.Find(key)) return b->format();
  throw std::logic_error("ConfigValueText: unknown key " + key);
}

std::vector<std::string> ConfigKeyNames() {
  Config defaults;
  std::vector<std::string> names;
  const OptionTable table = ConfigTable(defaults);
  for (const auto& b : table.Bindings()) names.push_back(b.key);
  return names;
}

}  // namespace openable
