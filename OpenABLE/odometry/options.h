// The odometry of the SNAPS chain as the configuration gives it (the Odometry_* keys and
// Snaps_odometry, docs/odometry.md), and the option structs of each odometry it sets.
#pragma once

#include <string>

#include "OpenABLE/base/enum_names.h"
#include "OpenABLE/odometry/mono_odometry.h"
#include "OpenABLE/odometry/stereo_odometry.h"

namespace openable::odometry {

// Where the trajectory of the SNAPS chain comes from: a file (none), or the images.
enum class OdometryKind { kNone, kMono, kStereo };
OPENABLE_ENUM_NAMES(OdometryKind, "", "mono", "stereo")

// Monocular odometry: where the length of each step comes from.
enum class StepScale { kTruth, kStep, kNone };
OPENABLE_ENUM_NAMES(StepScale, "truth", "step", "none")

struct OdometryOptions {
  OdometryKind kind = OdometryKind::kNone;  // Snaps_odometry
  std::string calibration;         // KITTI calib.txt of rectified images (Odometry_calibration)
  double calibration_scale = 1.0;  // multiplies its intrinsics, [0.01, 10]
  StepScale scale = StepScale::kTruth;  // monocular: step lengths from the ground truth, ...
  double step_length = 1.0;             // metres per frame with StepScale::kStep, >= 0
  std::string features;                 // ORB or SIFT, any case; empty: each odometry's default
  int max_features = 2000;              // keypoints per frame, >= 10
  double ratio_test = 0.8;              // Lowe's ratio test, [0.1, 1]
  double ransac_threshold = 0.0;        // pixels, [0, 100]; 0: each odometry's default
  int min_inliers = 0;           // fewest inliers of a step, >= 0; 0: each odometry's default
  std::string matcher = "sgbm";  // stereo disparity: sgbm or bm
  bool wls_filter = true;        // stereo: weighted-least-squares disparity filter
  int num_disparities = 64;      // stereo: disparity range, a multiple of 16 in [16, 256]
  double max_depth = 80.0;       // stereo: farther points are not used in PnP, >= 1 metre

  // The options of each odometry: its defaults, with the keys given here (empty or 0 keeps a
  // default).
  MonoOdometryOptions Mono() const;
  StereoOdometryOptions Stereo() const;
  // Throws InputError naming the key of a value that either odometry refuses.
  void Check() const;
};

}  // namespace openable::odometry
