#include "descriptors/dldb.h"

#include <stdexcept>
#include <string>

namespace openable {

void DldbDescriptor::DescribePatch(const cv::Mat& patch, cv::Mat row) const {
  const int half = ldb_.Width();
  cv::Mat channel;
  cv::extractChannel(patch, channel, 0);
  ldb_.Describe(channel, row.colRange(0, half));
  cv::extractChannel(patch, channel, 1);
  ldb_.Describe(channel, row.colRange(half, 2 * half));
}

}  // namespace openable
