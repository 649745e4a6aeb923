// D-LDB: LDB over a grey patch and over its disparity patch, concatenated (R. Arroyo et al.,
// "Fast and effective visual place recognition using binary codes and disparity information",
// IEEE/RSJ IROS 2014, ABLE-S; reference [9] of the OpenABLE paper). As the original OpenABLE
// builds it, not interleaved as in the paper: the same tests in another bit order, invisible to
// the Hamming distance, and the first half of a row is exactly the grey LDB row. The patch is
// CV_8UC2 (grey, disparity normalised to 8 bits). docs/descriptors.md, "D-LDB".
#pragma once

#include <string>

#include "descriptors/descriptor.h"
#include "descriptors/ldb.h"

namespace openable {

class DldbDescriptor final : public Descriptor {
 public:
  // Same options and limits as LDB (Patch_size >= 16, Ldb_bits in [1, 1386]).
  explicit DldbDescriptor(const DescriptorOptions& options) : Descriptor(options), ldb_(options) {}

  std::string Name() const override { return "D-LDB"; }
  int Width() const override { return 2 * ldb_.Width(); }
  DescriptorKind Kind() const override { return DescriptorKind::kBinary; }
  int Channels() const override { return 2; }
  // `patch`: PatchSize() x PatchSize() CV_8UC2 (grey, disparity); `row`: 1 x Width() CV_8U.
  // Throws std::logic_error on anything else.

  // The LDB used for both halves.
  const LdbDescriptor& Ldb() const { return ldb_; }

 private:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;
  LdbDescriptor ldb_;
};

}  // namespace openable
