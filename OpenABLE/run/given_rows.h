// Features computed elsewhere (Descriptors_path, Descriptors_path_2): a .npy of one row per
// frame of a traversal, in place of describing its frames. float32 rows are matched by L2,
// uint8 rows as bits by Hamming, as the run's own descriptors of those kinds; every later stage
// (sequences, the evaluation, the matches, the report) is the same.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "descriptors/descriptor.h"

namespace openable {

// The rows of one traversal from the bytes of a .npy file: 2-D, float32 ('<f4') or uint8
// ('|u1'), at least one row and one column, every value finite. Throws InputError in one line
// naming `key` and `path`: another dtype (with the NumPy call that converts it), shape, NaN or
// infinity (naming the row), no rows, a damaged file.
cv::Mat ReadGivenRows(const std::string& path, const std::string& key);

// The descriptor of rows given by files: its name is "NPY", its width and kind those of the
// rows (float: L2; bytes: Hamming); it describes nothing (Describe is a logic error) and gives
// each traversal's rows (GivenRows).
class GivenRowsDescriptor : public Descriptor {
 public:
  // `rows`: one matrix per traversal, all of one width and type (checked by the caller).
  GivenRowsDescriptor(const DescriptorOptions& options, std::vector<cv::Mat> rows);
  std::string Name() const override { return "NPY"; }
  int Width() const override { return rows_.front().cols; }
  DescriptorKind Kind() const override {
    return rows_.front().type() == CV_32F ? DescriptorKind::kFloat : DescriptorKind::kBinary;
  }
  const cv::Mat* GivenRows(int traversal) const override {
    return traversal >= 0 && traversal < static_cast<int>(rows_.size()) ? &rows_[traversal]
                                                                        : nullptr;
  }

 protected:
  void DescribePatch(const cv::Mat& patch, cv::Mat row) const override;

 private:
  std::vector<cv::Mat> rows_;
};

}  // namespace openable
