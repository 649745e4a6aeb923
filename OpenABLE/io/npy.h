// NumPy .npy files (https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html):
// the one place that writes and reads them. Test_OpenABLE's matrices (Npy_name) and matches
// (Matches_name) are written here; openable_evaluate, the ground truth and SNAPS read matrices
// through DecodeNpyMatrix (OpenABLE/evaluation/matrix_file.h reads the file).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

namespace openable {

// The header of a version 1.0 .npy file: magic, version, length and the dict
// {'descr': <descr>, 'fortran_order': False, 'shape': <shape>, } padded with spaces so that
// the data starts at a multiple of 64 bytes. `descr` and `shape` are Python literals
// ("'<f4'", "(3, 4)"; a structured dtype "[('query', '<i4'), ...]", a vector "(5,)").
std::string NpyHeaderOf(const std::string& descr, const std::string& shape);
// Bytes of a NumPy .npy file (format version 1.0, little-endian float32, C order) holding
// `m` (CV_32FC1).
std::string EncodeNpy(const cv::Mat1f& m);
// The header alone (magic, version, dictionary) of a rows x cols float32 .npy; the data
// follows it in C order.
std::string NpyHeader(int rows, int cols);

// A 2-D numeric matrix from the bytes of a .npy file, as float: versions 1.0-3.0; dtypes bool,
// u1, i1, u2, i2, u4, i4, u8, i8, f4, f8, little-endian or '|'; C or Fortran order. Throws
// InputError with one line beginning with `where` on a bad magic, version, header, dtype,
// shape or truncated data.
cv::Mat1f DecodeNpyMatrix(std::string_view data, const std::string& where);

}  // namespace openable
