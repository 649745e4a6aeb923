// A stereo camera as a frame source: left and right image folders paired by position,
// rectified, with the disparity of each pair.
#pragma once

#include <memory>
#include <string>

#include "OpenABLE/io/frame_source.h"
#include "OpenABLE/stereo/calibration.h"
#include "OpenABLE/stereo/disparity.h"
#include "OpenABLE/stereo/rectification.h"

namespace openable {

// Everything a stereo source needs beside its folders.
struct StereoSourceOptions {
  double alpha = 0.0;  // stereoRectify's free scaling (see StereoRectifier): 0, no black borders
  // false skips SGBM (channel 1 of every frame is then 0): descriptors other than D-LDB read
  // only the rectified left image.
  bool compute_disparity = true;
};

// Opens the stereo folders `left` and `right` (Images_path_left, Images_path_right): the
// images of each (ListImages with `extension`) are paired by position in natural order, and
// the positions [first, last) are kept (last = -1: to the end), as Initial_image and
// Final_image do for one folder.
//
// Opening reads the first left image to learn the image size, checks that `calibration` fits
// it (CheckCalibrationFits) and computes the rectification maps once. The disparity options
// are DisparityOptions::ForWidth(width).
//
// Read(i) reads pair i and returns a CV_32FC2 frame of the left image's size: channel 0 the
// rectified left image, grey, in [0, 1]; channel 1 its disparity, NormalizeDisparity of the
// SGBM disparity, in [0, 1) (0 everywhere without compute_disparity). FrameName(i) is the left
// file's path. Reads are thread-safe.
//
// Throws InputError (one line naming the key, the folders and the counts) when a folder is
// missing or empty, when the two folders hold different numbers of images, when the range is
// outside them, or when the calibration does not fit; Read throws InputError naming the
// frame when an image cannot be decoded or when the left and right images (or the pair and
// the first left image) differ in size.
std::unique_ptr<FrameSource> OpenStereoFolders(const std::string& left, const std::string& right,
                                               const std::string& extension, int first, int last,
                                               const StereoCalibration& calibration,
                                               const StereoSourceOptions& options = {});

// The same over any two frame sources of one size (e.g. two image topics of a ROS bag,
// OpenBag): pairs by position, which must hold as many frames. `left_key` and `right_key` name
// the Config.txt keys in messages. Reads are thread-safe when both sources' are; Timestamp(i)
// is the left frame's.
std::unique_ptr<FrameSource> OpenStereoSources(std::unique_ptr<FrameSource> left,
                                               std::unique_ptr<FrameSource> right,
                                               const StereoCalibration& calibration,
                                               const StereoSourceOptions& options,
                                               const std::string& left_key,
                                               const std::string& right_key);

// The parts of one stereo pair, for tests and tools: the pair rectified and its disparity.
struct StereoPair {
  cv::Mat left_rectified, right_rectified;  // CV_8UC1
  cv::Mat1f disparity;                      // pixels, 0 where invalid
};

// Rectifies a CV_8UC1 pair and computes its disparity, as the stereo source does.
StereoPair ProcessStereoPair(const StereoRectifier& rectifier, const DisparityOptions& options,
                             const cv::Mat& left, const cv::Mat& right);

}  // namespace openable
