// What one odometry step did, for logs, benchmarks and tests.
#pragma once

#include <string>

namespace openable::odometry {

struct StepStats {
  int features = 0;    // keypoints detected in the new frame
  int matches = 0;     // previous-to-current matches kept by the ratio test (and, for stereo,
                       // with a usable depth)
  int inliers = 0;     // RANSAC inliers of the accepted model (0 on the first frame)
  double seconds = 0;  // wall time of the step
  bool ok = true;      // false: the motion was not estimated (constant-velocity fallback)
  std::string note;    // why ok is false, or "first frame"
};

}  // namespace openable::odometry
