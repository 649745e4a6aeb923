// DenseVLAD: a training-free global descriptor that survives a change of viewpoint and of light
// (Torii, Arandjelovic, Sivic, Okutomi, Pajdla, "24/7 place recognition by view synthesis",
// CVPR 2015; VLAD of Jegou et al., CVPR 2010, intra-normalised as in Arandjelovic and Zisserman,
// "All about VLAD", CVPR 2013): dense RootSIFT on the shrunk frame at Scales(), aggregated over
// kCentres visual words learnt from the run's own reference traversal (Learn, no ground truth);
// rows of kCentres x 128 floats matched by L2. Torii et al.'s PCA whitening is left out: a few
// hundred frames cannot estimate it. docs/descriptors.md, "DenseVLAD".
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

class DenseVladDescriptor : public Descriptor {
 public:
  static constexpr int kWidth = 320;          // frames shrunk to at most this width
  static constexpr int kStep = 4;             // grid step of the dense keypoints, pixels
  static constexpr int kCentres = 64;         // visual words of the vocabulary
  static constexpr int kLearnFrames = 40;     // frames Learn is best given
  static constexpr int kLearnPerFrame = 600;  // descriptors kept of each for k-means
  static constexpr float kSize = 2.0f;        // SIFT keypoint size (12-pixel windows)
  // The scales the frame is described at (1: the shrunk frame; below: smaller copies of it).
  static const std::vector<double>& Scales();

  explicit DenseVladDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "DENSEVLAD"; }
  int Width() const override { return kCentres * 128; }
  DescriptorKind Kind() const override { return DescriptorKind::kFloat; }
  // Any size (the cell as it is): the descriptor shrinks it itself, keeping its aspect.
  cv::Size InputSize() const override { return cv::Size(); }
  bool Learns() const override { return true; }
  int LearnFrames() const override { return kLearnFrames; }
  // Learns the vocabulary by k-means (seeded: the same patches give the same words) over the
  // RootSIFT descriptors of `patches` (kLearnPerFrame of each, evenly spread). Call before any
  // Describe and not while one runs. Throws InputError when the patches hold fewer descriptors
  // than words (frames too small or too few).
  void Learn(const std::vector<cv::Mat>& patches) const override;
  // A digest of the vocabulary ("" before Learn): the rows depend on the frames it was learnt from.
  std::string Fingerprint() const override { return fingerprint_; }

  // The dense RootSIFT descriptors of `patch` (CV_8UC1): n x 128 CV_32F, each row of unit L2
  // norm (or zero where the patch is flat).
  static cv::Mat DenseRootSift(const cv::Mat& patch);
  // The VLAD vector (1 x centres.rows * 128) of `local` (n x 128) over `centres`, each word's
  // residual sum L2-normalised, then the whole.
  static cv::Mat1f Vlad(const cv::Mat1f& local, const cv::Mat1f& centres);
  const cv::Mat1f& Vocabulary() const { return centres_; }

 protected:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;

 private:
  mutable cv::Mat1f centres_;  // kCentres x 128, set by Learn
  mutable std::string fingerprint_;
};

}  // namespace openable
