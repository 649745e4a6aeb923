#include "OpenABLE/run/given_rows.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/input_file.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/io/npy.h"

namespace openable {

cv::Mat ReadGivenRows(const std::string& path, const std::string& key) {
  const std::string where = key + " " + Quoted(path);
  const std::string bytes =
      ReadInputFile(path, where, "expected a .npy of one descriptor row per frame");
  const NpyHeaderInfo header = ReadNpyHeader(bytes, where);
  const bool floats = header.descr == "<f4";
  if (!floats && header.descr != "|u1")
    throw InputError(where + ": dtype " + Quoted(header.descr) +
                     "; expected float32 ('<f4', rows matched by L2) or uint8 ('|u1', binary "
                     "rows matched by Hamming): save rows.astype(numpy.float32), or packed bits "
                     "as numpy.packbits(bits, axis=1)");
  if (header.shape.size() != 2)
    throw InputError(where + ": shape " + NpyShapeText(header.shape) +
                     "; expected (frames, width): one row per frame");
  if (header.shape[0] == 0 || header.shape[1] == 0)
    throw InputError(where + ": shape " + NpyShapeText(header.shape) +
                     " holds no rows; expected one row per frame, each of one value or more");
  // Read as floats (DecodeNpyMatrix checks the sizes against the bytes), then back to bytes
  // for uint8 rows: 0..255 are exact in float.
  const cv::Mat1f values = DecodeNpyMatrix(bytes, where);
  for (int r = 0; r < values.rows; ++r)
    for (int c = 0; c < values.cols; ++c)
      if (!std::isfinite(values(r, c)))
        throw InputError(where + ": row " + std::to_string(r) + " holds " +
                         (std::isnan(values(r, c)) ? "NaN" : "an infinity") + " at column " +
                         std::to_string(c) + "; expected finite values");
  if (floats) return values;
  cv::Mat bytes_rows;
  values.convertTo(bytes_rows, CV_8U);
  return bytes_rows;
}

GivenRowsDescriptor::GivenRowsDescriptor(const DescriptorOptions& options,
                                         std::vector<cv::Mat> rows)
    : Descriptor(options), rows_(std::move(rows)) {
  if (rows_.empty()) throw std::logic_error("GivenRowsDescriptor: no rows");
}

void GivenRowsDescriptor::DescribePatch(const cv::Mat&, cv::Mat) const {
  throw std::logic_error("NPY: the rows come from Descriptors_path; nothing is described");
}

}  // namespace openable
