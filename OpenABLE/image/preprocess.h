// Preprocessing of a frame before description.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "OpenABLE/image/robustness.h"

namespace openable {

// Grey 8-bit version of a frame as given by a FrameSource (CV_32FC1 or CV_32FC3 BGR in
// [0, 1]): OpenCV's luma weights (0.299 R + 0.587 G + 0.114 B), rounded to [0, 255]. A stereo
// frame (CV_32FC2: rectified left grey, disparity; OpenABLE/stereo/stereo_source.h) gives its
// channel 0, so every descriptor describes the rectified left image.
// Throws std::logic_error on any other type.
cv::Mat1b ToGray8(const cv::Mat& frame);

// The grey 8-bit image of an image a program gives (the online detector, verification):
// CV_8UC1, CV_8UC3 (BGR), CV_32FC1 or CV_32FC3 in [0, 1]. 8-bit images are first scaled to
// [0, 1] floats, as frame sources give them, so that the grey conversion is ToGray8's, the one
// Test_OpenABLE applies. Throws InputError "<what> is empty / has OpenCV type ..." otherwise.
cv::Mat1b GreyOfImage(const cv::Mat& image, const std::string& what);

// Colour 8-bit version of a frame as given by a FrameSource (CV_8UC3, BGR; value x 255,
// rounded): the image a network describes (descriptors/onnx.h). A grey frame gives its grey
// value in all three channels; a stereo frame (CV_32FC2), its rectified left image so.
// Throws std::logic_error on any other type.
cv::Mat ToColour8(const cv::Mat& frame);

// The colour 8-bit image (CV_8UC3, BGR) of an image a program gives, for a network
// (descriptors/onnx.h): the types GreyOfImage takes, 8-bit colour as it is, grey in all three
// channels, floats as ToColour8 converts a frame. Throws InputError as GreyOfImage.
cv::Mat ColourOfImage(const cv::Mat& image, const std::string& what);

// Both channels of a stereo frame (CV_32FC2 in [0, 1]) as CV_8UC2 (value x 255, rounded): the
// patch D-LDB describes. Throws std::logic_error on any other type.
cv::Mat ToGrayDisparity8(const cv::Mat& frame);

}  // namespace openable

namespace openable {

// Illumination invariant image of Eq. 6 of the OpenABLE paper (after Maddern et al., "Illumination
// invariant imaging", ICRA-W 2014): I = log(G) - alpha log(B) - (1 - alpha) log(R), per pixel of a
// colour frame (CV_32FC3, BGR in [0, 1], as a FrameSource gives it).
// Chosen here (the paper gives no 8-bit mapping): channel values are floored at 1/510 (half an
// 8-bit step) so that log stays finite, and I is mapped to 8 bits as 255 (0.5 + I / 2), rounded
// and saturated: 0.5 is Maddern's offset, and log-chromaticity ratios between e^-1 and e^1 fill
// 0..255 (the range of real scenes: a pixel whose green is e times its weighted red-blue mean
// is white). Throws InputError (without a file name: the caller adds it) on a frame that is not
// colour, or whose three channels are equal everywhere (a grey image stored as colour: Eq. 6
// gives a constant image).
cv::Mat1b IlluminationInvariant(const cv::Mat& frame, double alpha);

// Alpha of Eq. 7 from the peak spectral responses of the camera's red, green and blue channels
// (nanometres): alpha = (lB / lG - lB / lR) / (1 - lB / lR). KITTI's PointGrey Flea2 (610, 535,
// 470 nm) gives 0.4706. Throws InputError naming the keys Lambda_red, Lambda_green, Lambda_blue
// unless 0 < blue < green < red (which puts alpha in (0, 1)).
double AlphaFromPeakResponses(double red_nm, double green_nm, double blue_nm);

// The layer radii of a side-window fusion written as text ("1,2,3": integers in [1, 50],
// 1 to 16 layers, spaces allowed). Throws a one-line InputError naming Side_window_radii.
std::vector<int> ParseSideWindowRadii(const std::string& text);

// How each frame is prepared before description (the keys Illumination_invariance, Alpha,
// Lambda_*, Side_window, Side_window_radii and Noise_*; docs/descriptors.md).
struct PreprocessOptions {
  bool illumination_invariance = false;  // describe Eq. 6's image instead of the grey one
  double alpha = 0.47;                   // alpha of Eq. 6, [0, 1] (KITTI's PointGrey Flea2)
  // Peak spectral responses of the red, green and blue channels, nm, [0, 2000]: all three
  // (then Eq. 7 gives alpha) or none (0).
  double lambda_red = 0, lambda_green = 0, lambda_blue = 0;
  bool side_window = false;                 // side-window multilayer fusion (robustness.h)
  std::string side_window_radii = "1,2,3";  // its layer radii, ParseSideWindowRadii
  NoiseOptions noise;                       // noise for robustness studies (robustness.h)

  // Alpha of Eq. 6: by Eq. 7 from the peak responses when they are given, else `alpha`.
  double Alpha() const;
  // The radii of the side-window layers; empty when side_window is off.
  std::vector<int> SideWindowRadii() const;
  // Throws InputError naming the key of a value out of range, peak responses given in part or
  // out of order, or radii that do not parse (when side_window is on).
  void Check() const;
};

}  // namespace openable
