// Stereo calibration in the original OpenABLE's format, checked before any work.
//
// The file is OpenCV FileStorage YAML (first line "%YAML:1.0") with the matrices written as
// opencv-matrix nodes:
//   ML, MR  3x3 camera matrices of the left and right cameras (fx 0 cx; 0 fy cy; 0 0 1)
//   DL, DR  5x1 (or 1x5) distortion coefficients k1 k2 p1 p2 k3 (OpenCV's radial-tangential)
//   R       3x3 rotation and
//   T       3x1 (or 1x3) translation taking a point from the left camera's frame to the right
//           camera's frame (x_right = R x_left + T), as cv::stereoCalibrate returns and
//           cv::stereoRectify expects; any unit (metres, millimetres): only its direction
//           matters to rectification
//   colormap, use_log  optional integers for rendering a disparity image (cv::ColormapTypes
//           number 0-21 or -1 for grey; 1 renders log(1 + d) instead of d). Read and checked;
//           the pipeline writes no disparity image (docs/cameras.md).
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace openable {

struct StereoCalibration {
  std::string path;                     // file it was read from (for messages)
  cv::Matx33d left_camera;              // ML
  cv::Matx33d right_camera;             // MR
  cv::Vec<double, 5> left_distortion;   // DL: k1 k2 p1 p2 k3
  cv::Vec<double, 5> right_distortion;  // DR
  cv::Matx33d rotation;                 // R: right_from_left rotation
  cv::Vec3d translation;                // T: right_from_left translation
  int colormap = -1;                    // -1 grey, else a cv::ColormapTypes number 0-21
  int use_log = 0;                      // 1: render log(1 + disparity)
};

// Reads and checks a calibration file. Throws InputError with one line naming the file, the
// key, the value and what was expected when the file is missing or unreadable, is not
// OpenCV YAML, lacks a key, holds a matrix of the wrong size or a non-finite value, a camera
// matrix with a focal length <= 0 or a last row other than 0 0 1, an R that is not a
// rotation (|R^T R - I| > 1e-3 or det R <= 0), a zero T, or colormap/use_log out of range.
StereoCalibration LoadStereoCalibration(const std::string& path);

// The rule of CheckCalibrationFits for one camera (`camera` names it in the message: "ML").
void CheckPrincipalPointFits(const std::string& calibration, const std::string& camera, double cx,
                             double cy, const cv::Size& size, const std::string& first_image);

// Checks that the calibration fits images of `image_size` (the size of the first left image,
// named `first_image` in the message). Rule: the principal point (cx, cy) of each camera lies
// inside the image, and more strictly in its middle half: width/4 <= cx <= 3 width/4 and
// height/4 <= cy <= 3 height/4. Real principal points sit near the centre; plain "inside"
// misses a calibration made for another resolution, e.g. full-size KITTI intrinsics
// (607, 185) on the half-size 620x188 frames, which this rule catches. Throws InputError
// "calibration does not fit the images" naming the file, the image size, the size the
// calibration suits (2 cx x 2 cy) and the point.
void CheckCalibrationFits(const StereoCalibration& calibration, const cv::Size& image_size,
                          const std::string& first_image);

}  // namespace openable
