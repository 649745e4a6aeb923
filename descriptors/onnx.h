// ONNX: a network of the user's (NetVLAD, CosPlace, MixVPR, ...) as a global descriptor, run by
// OpenCV's DNN module (docs/descriptors.md, "Bring your own descriptor"). A frame (or each
// cell of Description_type grid, each sub-panorama) is resized to the network's input,
// converted to its channels (RGB, BGR or grey), scaled to [0, 1], standardised by a mean and a
// standard deviation per channel, and run through the network in batches; the output, one
// vector per image, is a float row matched by L2 (L2-normalised with Model_normalize).
#pragma once

#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

// A network as the DNN module holds it (libopenable_dnn.so, descriptors/onnx_module.cc): the
// module's reader returns one, so that OpenCV's DNN library is loaded only by runs that use a
// model. Not thread-safe: OnnxDescriptor serialises its calls.
class OnnxNetwork {
 public:
  virtual ~OnnxNetwork() = default;
  // The outputs of the N x C x H x W float blob `input` (the network's first output).
  // Throws cv::Exception when the network cannot run on it.
  virtual cv::Mat Forward(const cv::Mat& input) = 0;
};

class OnnxDescriptor : public Descriptor {
 public:
  // Loads options.model_path and runs it once on blank images, to learn its output width and
  // whether it takes batches. Throws InputError in one line naming the key and the value: a
  // missing or unreadable file, a file that is not ONNX or that OpenCV cannot import (its
  // reason quoted), an input size the network refuses, an output that is not one vector per
  // image, bad Model_input_size, Model_channels, Model_mean, Model_std or Model_batch.
  explicit OnnxDescriptor(const DescriptorOptions& options);

  std::string Name() const override { return "ONNX"; }
  int Width() const override { return width_; }
  DescriptorKind Kind() const override { return DescriptorKind::kFloat; }
  cv::Size InputSize() const override { return input_; }
  int Channels() const override { return 3; }
  std::string Fingerprint() const override { return fingerprint_; }
  void DescribeBatch(const std::vector<cv::Mat>& patches, cv::Mat rows) const override;
  int PreferredBatch() const override { return batch_; }

  // The N x C x H x W blob of `patches` (BGR, InputSize()) as the network takes it.
  cv::Mat Blob(const std::vector<cv::Mat>& patches) const;

 protected:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;

 private:
  // Runs the network on `patches` into `rows` (one row each): forward, checks, normalisation.
  void Run(const std::vector<cv::Mat>& patches, cv::Mat rows) const;

  std::string path_;
  cv::Size input_;
  enum class Order { kRgb, kBgr, kGrey } order_ = Order::kRgb;
  std::vector<float> mean_, std_;  // one value per network channel
  bool normalize_ = true;
  int batch_ = 1;
  int width_ = 0;
  std::string fingerprint_;
  std::unique_ptr<OnnxNetwork> network_;
  mutable std::mutex mutex_;  // the network runs one batch at a time
};

}  // namespace openable
