#include "descriptors/dldb.h"

#include <stdexcept>
#include <string>

namespace openable {

void DldbDescriptor::Describe(const cv::Mat& patch, cv::Mat row) const {
  const int p = PatchSize();
  if (patch.type() != CV_8UC2 || patch.rows != p || patch.cols != p) {
    throw std::logic_error("D-LDB: expected a " + std::to_string(p) + " x " + std::to_string(p) +
                           " CV_8UC2 patch (grey, disparity), got " + std::to_string(patch.rows) +
                           " x " + std::to_string(patch.cols) + " " +
                           cv::typeToString(patch.type()));
  }
  if (row.type() != CV_8UC1 || row.rows != 1 || row.cols != Width()) {
    throw std::logic_error("D-LDB: expected a 1 x " + std::to_string(Width()) +
                           " CV_8UC1 row, got " + std::to_string(row.rows) + " x " +
                           std::to_string(row.cols) + " " + cv::typeToString(row.type()));
  }
  const int half = ldb_.Width();
  cv::Mat channel;
  cv::extractChannel(patch, channel, 0);
  ldb_.Describe(channel, row.colRange(0, half));
  cv::extractChannel(patch, channel, 1);
  ldb_.Describe(channel, row.colRange(half, 2 * half));
}

}  // namespace openable
