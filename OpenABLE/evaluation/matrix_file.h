// Reading matrices saved by OpenABLE or given as ground truth.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace openable {

// Reads a 2-D numeric matrix as float: NumPy .npy (version 1.0-3.0; dtypes bool, u1, i1, u2,
// i2, u4, i4, u8, i8, f4, f8, little-endian or '|'; C or Fortran order), a text file of
// whitespace- or comma-separated numbers, one row per line ('#' comments, blank lines
// ignored, every row the same length), or an image that OpenCV reads (.png, .bmp, .pgm, .tif,
// ...: grey level, colour converted to grey). The kind is chosen by extension (.npy, .txt /
// .csv / .dat, image extensions). Throws InputError with one line naming the file (and line,
// for text) on a missing file, an unsupported dtype or extension, ragged rows or a value that
// is not a number.
cv::Mat1f ReadMatrixFile(const std::string& path);

// The size of the matrix ReadMatrixFile would read, without reading a .npy file's cells (its
// header alone; other kinds are read whole). Throws as ReadMatrixFile does.
cv::Size MatrixFileSize(const std::string& path);

}  // namespace openable
