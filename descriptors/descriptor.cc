#include "descriptors/descriptor.h"

#include <cstddef>
#include <stdexcept>
#include <string>

#include "OpenABLE/base/error.h"

namespace openable {
namespace {

std::string Shape(const cv::Mat& m) {
  return std::to_string(m.rows) + " x " + std::to_string(m.cols) + " " + cv::typeToString(m.type());
}

}  // namespace

void DescriptorOptions::Check() const {
  if (patch_size < 16 || patch_size > 1024) {
    throw InputError("Patch_size: " + std::to_string(patch_size) +
                     " is out of range; expected an integer in [16, 1024]");
  }
  if (ldb_bits < 1 || ldb_bits > 1386) {
    throw InputError("Ldb_bits: " + std::to_string(ldb_bits) +
                     " is out of range; expected an integer in [1, 1386]");
  }
  if (model_batch < 1 || model_batch > 1024) {
    throw InputError("Model_batch: " + std::to_string(model_batch) +
                     " is out of range; expected an integer in [1, 1024]");
  }
  if (sad_patch < 2 || sad_patch > 64) {
    throw InputError("Sad_patch: " + std::to_string(sad_patch) +
                     " is out of range; expected an integer in [2, 64]");
  }
}

Descriptor::Descriptor(const DescriptorOptions& options) : patch_size_(options.patch_size) {
  options.Check();
}

void Descriptor::CheckPatch(const cv::Mat& patch) const {
  const cv::Size size = InputSize();
  if (size.empty()) {
    if (patch.type() != CV_8UC(Channels()) || patch.rows < 16 || patch.cols < 16)
      throw std::logic_error(Name() + ": expected a " + cv::typeToString(CV_8UC(Channels())) +
                             " patch of at least 16 x 16, got " + Shape(patch));
    return;
  }
  if (patch.type() != CV_8UC(Channels()) || patch.rows != size.height || patch.cols != size.width) {
    throw std::logic_error(Name() + ": expected a " + std::to_string(size.height) + " x " +
                           std::to_string(size.width) + " " + cv::typeToString(CV_8UC(Channels())) +
                           " patch, got " + Shape(patch));
  }
}

void Descriptor::DescribeBatch(const std::vector<cv::Mat>& patches, cv::Mat rows) const {
  if (rows.rows != static_cast<int>(patches.size()))
    throw std::logic_error(Name() + ": " + std::to_string(patches.size()) + " patches for " +
                           std::to_string(rows.rows) + " rows");
  for (std::size_t i = 0; i < patches.size(); ++i)
    Describe(patches[i], rows.row(static_cast<int>(i)));
}

void Descriptor::Describe(const cv::Mat& patch, cv::Mat row) const {
  CheckPatch(patch);
  const int row_type = RowType(*this);
  if (row.type() != row_type || row.rows != 1 || row.cols != Width()) {
    throw std::logic_error(Name() + ": expected a 1 x " + std::to_string(Width()) + " " +
                           cv::typeToString(row_type) + " row, got " + Shape(row));
  }
  DescribePatch(patch, row);
}

}  // namespace openable
