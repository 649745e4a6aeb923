// Robustness to sensor noise and light: side-window multilayer pixel fusion, a
// preprocessing of the grey image before description, and noise injection into frames for
// robustness studies.
//
// Side-window fusion follows Algorithm 1 and Eq. 6 of "A Variable Radius Side Window Direct
// SLAM Method Based on Semantic Information" (side window strategy after Yin et al., CVPR 2019).
// From the paper:
//   - the (2r+1) x (2r+1) square S around each pixel p_i is divided into eight side windows
//     U, D, L, R, NW, NE, SW, SE of radius r, the pixel lying on a side (U, D, L, R: half
//     squares, (r+1) x (2r+1)) or on a corner (NW, NE, SW, SE: quarter squares, (r+1) x (r+1));
//   - q_n is the mean of the pixels of window n; the output is q_s with
//     s = argmin_n |q_n - p_i| (L1 distance, Eq. 6);
//   - layers are stacked like a CNN (the output of one layer is the input of the next).
// Chosen here (the paper leaves these open):
//   - every window contains the centre pixel (Yin et al.'s definition; the paper's Fig. 2 puts
//     p_i "on the side or corner of the window");
//   - each layer reads only its input image (all pixels of a layer are computed from the same
//     input, not updated in place);
//   - one radius per layer (Algorithm 1 takes one r; Algorithm 2 varies it between layers: the
//     first half small, the second half larger. Its semantic part, YOLO on semistatic
//     objects, is not implemented);
//   - near the image border a window is clipped to the image and its mean is over the pixels
//     inside (the clipped window always holds p_i);
//   - ties (|q_n - p_i| within 1e-9 of the smallest) go to the first window in the order
//     U, D, L, R, NW, NE, SW, SE (the order of Eq. 6);
//   - values stay real (double) between layers and are rounded to 8 bits (half up) at the end.
// Each layer is O(pixels): box sums from an integral image.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace openable {

// One layer of side-window fusion of radius r >= 1 on a real image (CV_64FC1).
cv::Mat1d SideWindowLayer(const cv::Mat1d& image, int r);

// Stacked layers, radii[k] being the radius of layer k (empty: the image unchanged). On an 8-bit
// grey image; a two-channel image (grey + disparity, D-LDB) is fused on channel 0 only.
// Throws std::logic_error on another type or a radius below 1.
cv::Mat SideWindowFusion(const cv::Mat& image, const std::vector<int>& radii);

// Noise for robustness studies, applied to a frame as a FrameSource gives it (CV_32FC1, or C3
// colour, in [0, 1]; of a stereo frame, CV_32FC2, only channel 0, the rectified left image:
// its disparity is computed from the clean pair). In this order:
//   1. overexposure: v = v (1 + overexposure), i.e. the exposure multiplied by 1 + overexposure
//      (1 doubles it: every value above 0.5 saturates at 1 in step 2);
//   2. Gaussian: v += N(0, gaussian) (gaussian is the variance, the paper's 0.003 on [0, 1]
//      intensities), independently per channel as on a sensor; values clipped to [0, 1];
//   3. salt-and-pepper: a fraction salt_pepper of the pixels (each independently with that
//      probability) set to 0 or 1 (even odds) in every channel.
// A colour frame's grey image (ToGray8's luma weights) then has about 0.45 x the variance.
struct NoiseOptions {
  double gaussian = 0.0;      // variance on [0, 1] intensities; 0 = off
  double salt_pepper = 0.0;   // fraction of pixels in [0, 1]; 0 = off
  double overexposure = 0.0;  // added exposure gain (v (1 + g)); 0 = off
  int seed = 0;
  bool Any() const { return gaussian > 0 || salt_pepper > 0 || overexposure > 0; }
};

// The RNG state of frame `frame` of traversal `stream` (0 Images_path, 1 Images_path_2):
// a mix (splitmix64) of the seed, the stream and the frame, so that the noise of a frame does
// not depend on the thread that describes it, and two traversals do not get the same noise
// for the same frame index.
uint64_t NoiseState(int seed, int stream, int frame);

// `frame` with the noise above (a new image; the input is not changed). Throws
// std::logic_error on a type other than CV_32FC1/2/3.
cv::Mat AddNoise(const cv::Mat& frame, const NoiseOptions& options, uint64_t state);

}  // namespace openable
