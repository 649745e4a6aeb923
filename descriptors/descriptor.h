// The one descriptor interface of OpenABLE.
//
// A descriptor turns a square grey patch (CV_8UC1, side = patch_size) into one row of
// Width() elements: bytes for binary descriptors (matched with the Hamming distance, Eq. 4 of
// the OpenABLE paper), floats for vector descriptors (matched with the L2 norm, Eq. 8), or
// bytes that are small integers (SeqSLAM's SAD, matched with the sum of absolute differences).
// The keypoint is the patch centre, with no dominant orientation and the patch as its scale,
// as ABLE computes its global descriptor.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace openable {

// What a row holds: bits (kBinary, CV_8U), floats (kFloat, CV_32F) or byte values (kBytes,
// CV_8U).
enum class DescriptorKind { kBinary, kFloat, kBytes };
// How rows are compared: Hamming for bits, L2 for floats, L1 (sum of absolute differences) for
// byte values.
enum class DistanceKind { kHamming, kL2, kL1 };

// Options every descriptor may read; defaults are those of the ABLE papers.
struct DescriptorOptions {
  std::string name = "LDB";  // registry name (descriptors/registry.h), any case
  int patch_size = 64;       // side of the square patch, pixels, 16..1024
  int ldb_bits = 256;        // LDB bits kept after selection, 1..1386 (32 bytes = 256 in ABLE-P)
  int sad_patch = 8;         // SAD: side of the normalised squares, pixels, 2..64 (SeqSLAM: 8)
  // ONNX (descriptors/onnx.h): a network of the user's, run by OpenCV's DNN module.
  std::string model_path;              // the .onnx file
  std::string model_input_size;        // "WxH" of the network's input; "": the model's own
  std::string model_channels = "rgb";  // rgb, bgr or grey: the channels the network takes
  std::string model_mean = "0.485,0.456,0.406";  // per channel, after scaling pixels to [0, 1]
  std::string model_std = "0.229,0.224,0.225";   // per channel (ImageNet's, as torchvision's)
  bool model_normalize = true;                   // L2-normalise each output row
  int model_batch = 16;                          // frames per forward pass, 1..1024
  // "NPY": rows computed elsewhere and given, not described (a map made by openable_map add
  // --descriptors): their width in elements and whether they are bytes of bits (Hamming) or
  // floats (L2). Not keys of a run, whose given rows come from Descriptors_path.
  int given_width = 0;
  bool given_binary = false;

  // Throws InputError naming the key (Patch_size, Ldb_bits, Sad_patch), the value and the
  // valid range.
  // Every descriptor's constructor calls it (through the base class) before building
  // anything; descriptors add their own limits (HOG: a multiple of 8). The name is checked by
  // CreateDescriptor.
  void Check() const;
};

class Descriptor {
 public:
  virtual ~Descriptor() = default;
  // Registry name, upper case as in Config.txt ("LDB", "ORB", ...).
  virtual std::string Name() const = 0;
  // Elements per row: bytes (kBinary, kBytes) or floats (kFloat).
  virtual int Width() const = 0;
  virtual DescriptorKind Kind() const = 0;
  DistanceKind Distance() const {
    switch (Kind()) {
      case DescriptorKind::kBinary:
        return DistanceKind::kHamming;
      case DescriptorKind::kFloat:
        return DistanceKind::kL2;
      case DescriptorKind::kBytes:
        break;
    }
    return DistanceKind::kL1;
  }
  // Side of the square patch this descriptor expects.
  int PatchSize() const { return patch_size_; }
  // The size of the image Describe takes: the square patch, or a network's input (ONNX);
  // empty for a descriptor that takes any size of at least 16 x 16 (DenseVLAD shrinks it
  // itself).
  virtual cv::Size InputSize() const { return cv::Size(patch_size_, patch_size_); }
  // Channels of the patch: 1 (grey) for every descriptor but D-LDB, whose patch has 2
  // (channel 0 grey, channel 1 disparity, both CV_8U; descriptors/dldb.h), and ONNX, whose
  // patch has 3 (the frame's colours, BGR, as OpenCV holds them).
  virtual int Channels() const { return 1; }
  // What else than the settings makes this descriptor's rows: a network's weights (a digest of
  // the model file); empty for the hand-crafted descriptors. Part of the descriptor cache's key.
  virtual std::string Fingerprint() const { return std::string(); }
  // Describes several patches at once into the rows of `rows` (patches.size() x Width()), as
  // Describe would one by one; a network runs them as one batch. Thread-safe.
  virtual void DescribeBatch(const std::vector<cv::Mat>& patches, cv::Mat rows) const;
  // The patches DescribeBatch is best given at once (1: no gain from batches).
  virtual int PreferredBatch() const { return 1; }
  // Whether the descriptor learns from frames before it describes (DenseVLAD's vocabulary,
  // learnt from the reference traversal): Learn must then be called first.
  virtual bool Learns() const { return false; }
  // Learns from `patches` (as Describe takes them, of frames spread over the reference
  // traversal). Called once before any Describe, never while one runs. The default does nothing.
  virtual void Learn(const std::vector<cv::Mat>& /*patches*/) const {}
  // The frames, spread over the reference traversal, Learn is best given (0: it learns nothing).
  virtual int LearnFrames() const { return 0; }
  // Rows given rather than described (features computed elsewhere, OpenABLE/run/given_rows.h):
  // those of traversal `traversal`, one per frame; nullptr for a descriptor that describes.
  virtual const cv::Mat* GivenRows(int /*traversal*/) const { return nullptr; }
  // Describes `patch` (CV_8UC(Channels()), PatchSize() x PatchSize()) into `row`, a 1 x Width()
  // matrix of CV_8U (binary) or CV_32F (float) that the caller allocated. Deterministic and
  // safe to call from several threads at once. Checks both once for every descriptor (after
  // OpenCV's Feature2D::compute around its virtual part) and throws std::logic_error naming
  // the descriptor on a patch or row of the wrong size or type; then DescribePatch does the
  // work.
  void Describe(const cv::Mat& patch, cv::Mat row) const;

 protected:
  // Checks `options` (DescriptorOptions::Check: InputError naming the key).
  explicit Descriptor(const DescriptorOptions& options);
  // std::logic_error naming the descriptor unless `patch` is CV_8UC(Channels()) of
  // PatchSize() x PatchSize().
  void CheckPatch(const cv::Mat& patch) const;
  // The descriptor proper, on a patch and a row that Describe has checked.
  virtual void DescribePatch(const cv::Mat& patch, cv::Mat row) const = 0;

 private:
  int patch_size_;
};

// CV type of one row element of a descriptor: CV_32F for kFloat, CV_8U otherwise.
inline int RowType(const Descriptor& d) {
  return d.Kind() == DescriptorKind::kFloat ? CV_32F : CV_8U;
}

}  // namespace openable
