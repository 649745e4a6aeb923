// Camera intrinsics for the odometry front-end of SNAPS and the reader of KITTI's calib.txt.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace openable::odometry {

// Pinhole intrinsics of an undistorted (or rectified) camera, pixels.
struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // [fx 0 cx; 0 fy cy; 0 0 1]
  cv::Matx33d K() const;
  // Throws InputError naming `what` unless fx, fy > 0 and every value is finite.
  void Check(const std::string& what) const;
};

// What the odometries need from a KITTI odometry calib.txt.
struct KittiCalibration {
  Intrinsics left;      // of camera 0 (P0), scaled
  double baseline = 0;  // metres, -P1(0,3) / P1(0,0) (camera 0 to camera 1)
};

// Reads KITTI's calib.txt: lines "P0: 12 numbers", "P1: 12 numbers", ... (row-major 3x4
// projection matrices of the rectified cameras; other lines such as "Tr:" are read and ignored
// when well formed). `scale` (> 0) multiplies the focal lengths and the principal point: 0.5
// for the half-size 620x188 frames of ../shared/datasets/kitti00_first1700. The baseline does
// not depend on `scale`. Throws InputError, one line naming file:line, when the file cannot be
// read, a line is not "<name>: 12 numbers", P0 or P1 is missing, or the values make no camera
// (focal <= 0, baseline <= 0).
KittiCalibration ReadKittiCalibration(const std::string& path, double scale);

}  // namespace openable::odometry
