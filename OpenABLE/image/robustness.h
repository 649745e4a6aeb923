// Robustness to sensor noise and light: side-window multilayer pixel fusion, a preprocessing of
// the grey image before description (Algorithm 1 and Eq. 6 of "A Variable Radius Side Window
// Direct SLAM Method Based on Semantic Information"; side windows after Yin et al., CVPR 2019),
// which smooths along edges but never across them; and noise injection into frames for
// robustness studies. Each fusion layer is O(pixels), from an integral image. The readings where
// the paper is open (windows hold p, clipping, ties, rounding): docs/descriptors.md, "Noise
// injection and side-window fusion".
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

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

// A synthetic night-like version of a day frame, for development and tests of settings meant
// to work from day to night (there is no night traversal among the shared datasets). It models
// what changes between a day image and a night image of the same place, in this order:
//   1. a small change of viewpoint (the camera is never in the same place twice): a random
//      similarity transform, scale up to 1 + `zoom`, shift up to `shift` of the frame's size,
//      rotation up to `rotation` degrees (border reflected);
//   2. light from elsewhere: the scene's reflectance (the day image) under artificial light,
//      E(x, y) = ambient + (1 - ambient) * ((1 - side) + side * u), u in [0, 1] rising towards
//      the lit side (the right, or the left when `from_left`); and a dark sky: the sky is the
//      brightest region by day and the darkest by night, so a pixel of the upper part of the
//      frame is darkened the more the brighter it was by day, by 1 - (1 - sky_floor) t v
//      (v its day intensity, t = 1 above half of `sky_height` of the frame's height, falling
//      linearly to 0 at `sky_height`);
//   3. a tone curve v -> v^gamma (gamma > 1: low light crushes the darker tones);
//   4. a colour cast (sodium or tungsten light): channel gains B, G, R (colour frames only);
//   5. the camera's automatic gain: the frame scaled so that its mean is `target_mean`;
//   6. sensor noise, as little light leaves it after that gain: shot noise of standard deviation
//      shot * sqrt(v / target_mean) and read noise of deviation `read` (on [0, 1]);
//   7. veiling glare: a fraction `glare` of the mean added everywhere (lower contrast), then
//      the frame rescaled by 1 / (1 + glare) and clipped to [0, 1].
// The defaults give a frame clearly darker in its upper part, lit from the right, noisy and of
// low contrast; `Strong()` a harder night. The result depends only on the frame and `state`.
struct NightOptions {
  double zoom = 0.04, shift = 0.02, rotation = 1.5;  // viewpoint
  double ambient = 0.25, side = 0.7;                 // light field
  bool from_left = false;
  double sky_floor = 0.1, sky_height = 0.5;
  double gamma = 1.6;
  double gain_b = 0.55, gain_g = 0.8, gain_r = 1.0;  // sodium-like cast
  double target_mean = 0.3, shot = 0.04, read = 0.02, glare = 0.25;
  static NightOptions Strong() {
    NightOptions o;
    o.zoom = 0.06, o.shift = 0.03, o.rotation = 2.5;
    o.ambient = 0.15, o.side = 0.85, o.sky_floor = 0.05, o.gamma = 2.0;
    o.shot = 0.07, o.read = 0.035, o.glare = 0.4;
    return o;
  }
};

// `frame` (CV_32FC1 or CV_32FC3 in [0, 1], as a FrameSource gives it) made night-like; a new
// image of the same size and type. Throws std::logic_error on another type.
cv::Mat MakeNightLike(const cv::Mat& frame, const NightOptions& options, uint64_t state);

}  // namespace openable
