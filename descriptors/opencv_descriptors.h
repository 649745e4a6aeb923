// ORB, BRISK and SIFT from OpenCV's features2d module (OpenCV 4.6; Rublee et al., ICCV 2011;
// Leutenegger, Chli and Siegwart, ICCV 2011; Lowe, IJCV 2004), each the global descriptor of the
// patch: one keypoint at the patch centre ((S - 1) / 2, (S - 1) / 2), angle 0, a scale chosen so
// that the descriptor covers the patch. The patch is padded by S / 2 + 1 pixels with
// cv::BORDER_REFLECT_101 so that OpenCV never drops the keypoint and samples just outside read a
// reflection. Describe() throws std::logic_error when OpenCV drops the keypoint or returns an
// unexpected width. docs/descriptors.md, "ORB, BRISK, SIFT (OpenCV)".
#pragma once

#include <memory>
#include <string>

#include "descriptors/descriptor.h"

namespace openable {

// ORB (oriented FAST and rotated BRIEF) without the orientation: cv::ORB with nlevels = 1,
// patchSize = edgeThreshold = S, WTA_K = 2, so the 256 intensity tests are drawn over the whole
// S x S patch (for patchSize != 31 OpenCV draws its own fixed pseudo-random pattern). The
// keypoint angle 0 is kept (ORB estimates orientation only when it detects). 32 bytes.
class OrbDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size when options.patch_size < 16.
  explicit OrbDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "ORB"; }
  int Width() const override { return 32; }
  DescriptorKind Kind() const override { return DescriptorKind::kBinary; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
};

// BRISK with its standard sampling pattern (60 points on rings of radius 0, 2.9, 4.9, 7.4 and
// 10.8 times 0.85 pixels at scale 1; 512 short-distance pairs, dMax = 5.85), 64 bytes.
//
// Scale: the keypoint size selects one of OpenCV's 64 discrete BRISK scales
// f = 30^(i / 64), i = 0..63, reached for size = 7.2 f. We take the scale whose outer ring of
// sample points (radius 9.18 f) is nearest the circle inscribed in the patch (radius S / 2), and
// pass exactly that size, so the pattern spans the patch without falling between two scales.
// For S = 64: i = 23, f = 3.39, outer ring radius 31.1 px. Below S = 19 the smallest scale
// (radius 9.18 px) is used.
//
// Orientation: OpenCV's BRISK::compute() always re-estimates the keypoint orientation from the
// pattern's long-distance pairs and overwrites the given angle; this option cannot be turned
// off. We build BRISK with the same pattern but with dMin larger than any pair distance, so the
// set of long pairs is empty, the estimated gradient is (0, 0) and the angle is 0. The 512
// short-pair tests are unchanged (with the default dMin = 8.2 this pattern reproduces
// cv::BRISK::create() bit for bit).
//
// The cv::BRISK object is costly to build (look-up tables for 64 scales x 1024 rotations), so
// instances are kept in a small pool owned by this object: one per thread describing at the
// same time, created on demand and released with the descriptor.
class BriskDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size when options.patch_size < 16.
  explicit BriskDescriptor(const DescriptorOptions& options);
  ~BriskDescriptor() override;

  std::string Name() const override { return "BRISK"; }
  int Width() const override { return 64; }
  DescriptorKind Kind() const override { return DescriptorKind::kBinary; }

  // Keypoint size passed to OpenCV for this patch size (see the class comment).
  float KeypointSize() const { return keypoint_size_; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  struct Pool;
  float keypoint_size_;
  std::unique_ptr<Pool> pool_;
};

// SIFT descriptor (4 x 4 cells of 8-bin orientation histograms), 128 floats, with no dominant
// orientation. cv::SIFT's descriptor grid is 4 cells of 3 * size / 2 pixels, 6 * size wide, so
// the keypoint size is S / 6 and the grid spans the patch exactly (16-pixel cells at S = 64).
// Trilinear interpolation lets pixels up to half a cell (S / 8) beyond the grid contribute, with
// weights falling from 1/2 to 0; these read the reflected border, so the descriptor depends only
// on the patch. The keypoint is on octave 0, layer 0 of SIFT's pyramid: the patch at its own
// resolution, smoothed by SIFT's base sigma 1.6.
class SiftDescriptor final : public Descriptor {
 public:
  // Throws InputError naming Patch_size when options.patch_size < 16.
  explicit SiftDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "SIFT"; }
  int Width() const override { return 128; }
  DescriptorKind Kind() const override { return DescriptorKind::kFloat; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
};

}  // namespace openable
