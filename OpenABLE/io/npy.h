// NumPy .npy files (https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html):
// the one place that writes and reads them. Test_OpenABLE's matrices (Npy_name) and matches
// (Matches_name) are written here; openable_evaluate, the ground truth and SNAPS read matrices
// through DecodeNpyMatrix (OpenABLE/evaluation/matrix_file.h reads the file). Object arrays
// (pickled) and .npz archives are read by npy_objects.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

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

// What the header of a .npy file says: the dtype ("<f4", "|b1", "|O"), the order, the shape
// and where the data start.
struct NpyHeaderInfo {
  std::string descr;
  bool fortran_order = false;
  std::vector<std::int64_t> shape;
  std::size_t data_offset = 0;
};
// Reads the magic, the version (1.0, 2.0 or 3.0), the header length and the dict of a .npy
// file. Throws InputError with one line beginning with `where` on a bad magic, version or
// dict, or a header longer than the file.
NpyHeaderInfo ReadNpyHeader(std::string_view data, const std::string& where);
// A shape as Python writes it: "(3, 4)", "(5,)", "()".
std::string NpyShapeText(const std::vector<std::int64_t>& shape);
// The little-endian unsigned integer of the `n` (<= 8) bytes at `p`: the lengths of .npy
// headers, the elements of '<' dtypes and, in npy_objects.h, pickles' and ZIP archives'
// fields.
std::uint64_t LittleEndianAt(const unsigned char* p, int n);

// A 2-D numeric matrix from the bytes of a .npy file, as float: versions 1.0-3.0; dtypes bool,
// u1, i1, u2, i2, u4, i4, u8, i8, f4, f8, little-endian or '|'; C or Fortran order. Throws
// InputError with one line beginning with `where` on a bad magic, version, header, dtype
// (an object array, '|O', is read by DecodeNpyObjects, npy_objects.h), shape or truncated data.
cv::Mat1f DecodeNpyMatrix(std::string_view data, const std::string& where);

}  // namespace openable
