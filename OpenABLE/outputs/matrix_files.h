// The matrix files of a run: the matrix as text (the .npy encoders are in OpenABLE/io/npy.h),
// and the matches file.
#pragma once

#include <cstdint>
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

// What the run's operating point made of each query's best match (the match of rank 1), per
// query of the block: accepted (its score is <= Match_threshold) and confirmed (accepted and,
// with Match_consistency, confirmed by independent queries; without it, every accepted match):
// the confirmed ones are the run's matches. Empty: nothing accepted.
struct MatchVerdicts {
  std::vector<std::uint8_t> accepted, confirmed;
};

// The verdicts of `matches` (AcceptedMatches, matching/bounded.h, over their rank-1 matches)
// at `threshold` (-1: none accepted), confirmed by `consistency` (null: Match_consistency 0);
// none at all when `accept_none` (the auto mode trusted no setting).
MatchVerdicts VerdictsOf(const std::vector<Match>& matches, double threshold,
                         const AgreementOptions* consistency, bool accept_none);

// Bytes of the matches file: .npy (structured array: query, reference int32; distance
// float32; rank int32; score float32; accepted, confirmed uint8) or .csv (header
// "query,reference,distance,rank,score,accepted,confirmed"). accepted and confirmed are those
// of `verdicts` for a match of rank 1, 0 for the others (docs/output_formats.md).
std::string EncodeMatches(const std::vector<Match>& matches, bool csv,
                          const MatchVerdicts& verdicts = {});

}  // namespace openable
