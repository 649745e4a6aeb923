// D-LDB: LDB over a grey patch and over its disparity patch, concatenated.
//
// Paper: R. Arroyo, P. F. Alcantarilla, L. M. Bergasa, J. J. Yebes and S. Bronte, "Fast and
// effective visual place recognition using binary codes and disparity information", IEEE/RSJ
// IROS 2014 (ABLE-S), reference [9] of the OpenABLE paper (Arroyo et al., ITSC 2016), which
// adds disparity comparisons (D_avg) to the binary tests of LDB.
//
// As the original OpenABLE builds it: the descriptor of a patch is the LDB
// string of its grey channel followed by the LDB string of its disparity channel, each with
// the same tests (descriptors/ldb.h, Ldb_bits bits), matched with one Hamming distance. So
// Width() = 2 x LDB width, and the first half of a D-LDB row is exactly the LDB row of the
// grey channel alone.
//
// Changed from the paper: the IROS paper interleaves the disparity tests with the intensity
// and gradient tests of each cell pair; concatenating two LDB strings holds the same tests
// (I_avg, G_x, G_y of the grey image and of the disparity image) in another bit order, which
// the Hamming distance does not see, and keeps the grey half identical to plain LDB.
//
// The patch is 2-channel (Channels() == 2): channel 0 grey, channel 1 disparity, both CV_8U;
// the disparity is normalised to 8 bits as OpenABLE/stereo/disparity.h describes. Outside the
// pipeline, OpenABLE/describe/describe.h builds such patches from the frames of a stereo source.
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
