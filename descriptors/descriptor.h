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
#include <string>
#include <vector>

#include <opencv2/core.hpp>

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
      case DescriptorKind::kBinary: return DistanceKind::kHamming;
      case DescriptorKind::kFloat: return DistanceKind::kL2;
      case DescriptorKind::kBytes: break;
    }
    return DistanceKind::kL1;
  }
  // Side of the square patch this descriptor expects.
  int PatchSize() const { return patch_size_; }
  // Channels of the patch: 1 (grey) for every descriptor but D-LDB, whose patch has 2
  // (channel 0 grey, channel 1 disparity, both CV_8U; descriptors/dldb.h).
  virtual int Channels() const { return 1; }
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
