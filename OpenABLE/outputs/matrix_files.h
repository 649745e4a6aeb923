// The matrix files of a run: the matrix as text (the .npy encoders are in OpenABLE/io/npy.h),
// and the matches file.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "matching/bounded.h"

namespace openable {

// Text of the matrix: one row per line, values separated by one space. Floats are written
// with 6 significant digits; CV_8U matrices (thresholded) as integers.
std::string EncodeText(const cv::Mat& m);

// The same text in pieces of 32 rows, formatted 16 pieces at a time in parallel, for writing a
// large matrix without holding its whole text (OutputBatch::Stage with a producer). `m` must
// outlive the object.
class TextChunks {
 public:
  explicit TextChunks(const cv::Mat& m);
  // The next piece (valid until the next call); false when the text is done.
  bool Next(std::string_view& piece);

 private:
  static constexpr int kBlockRows = 32, kBlocks = 16;
  cv::Mat m_;
  int next_row_ = 0;
  int blocks_ = 0, next_block_ = 0;  // formatted pieces, and the next one handed out
  std::vector<std::string> parts_ = std::vector<std::string>(kBlocks);  // buffers, reused
  std::vector<std::size_t> lengths_ = std::vector<std::size_t>(kBlocks);
};

// Bytes of the matches file: .npy (structured array: query, reference int32; distance
// float32; rank int32; score float32) or .csv (header "query,reference,distance,rank,score").
std::string EncodeMatches(const std::vector<Match>& matches, bool csv);

}  // namespace openable
