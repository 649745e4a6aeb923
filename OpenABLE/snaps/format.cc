#include <algorithm>
#include <cctype>

#include "OpenABLE/base/error.h"
#include "OpenABLE/snaps/trajectory.h"

namespace openable::snaps {

TrajectoryFormat ParseTrajectoryFormat(const std::string& name, const std::string& key) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "kitti") return TrajectoryFormat::kKitti;
  if (lower == "kitti-id") return TrajectoryFormat::kKittiWithId;
  if (lower == "tum") return TrajectoryFormat::kTum;
  throw InputError(key + ": " + Quoted(name) +
                   " is not a trajectory format; expected kitti (12 numbers per line), "
                   "kitti-id (frame number + 12 numbers) or tum (timestamp tx ty tz qx qy qz qw)");
}

std::string TrajectoryFormatName(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kKitti:
      return "kitti";
    case TrajectoryFormat::kKittiWithId:
      return "kitti-id";
    case TrajectoryFormat::kTum:
      return "tum";
  }
  return "?";
}

}  // namespace openable::snaps
