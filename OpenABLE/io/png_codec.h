// PNG without OpenCV's imgcodecs: decoding with libpng and encoding with zlib, in the program
// itself. imgcodecs brings GDAL, GDCM, OpenEXR and about 120 other shared libraries that every
// run would load at start-up (about 80 ms on the development machines), while the frames of
// almost every data set are PNG or JPEG; other formats load imgcodecs on first use
// (module_loader.h).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace openable {

// Decodes the bytes of a PNG file whose chunks are sound into 8- or 16-bit pixels, grey
// (grey, grey + alpha) or BGR (colour, palette, colour + alpha); alpha is dropped, bit depths
// 1, 2 and 4 are scaled to 8 bits, no gamma is applied: the pixels OpenCV's decoder gives for
// IMREAD_UNCHANGED once its alpha channel is dropped. Returns false with `why` set when libpng
// refuses the data.
bool DecodePng(const std::vector<unsigned char>& bytes, cv::Mat& image, std::string& why);

// The bytes of a PNG file of `image` (CV_8U or CV_16U; 1 channel grey, 3 BGR, 4 BGRA). Rows go
// through the Sub filter and deflate at level 1 with the run-length strategy (OpenCV's default
// settings); bands of rows are compressed in parallel as independent deflate blocks, joined
// into one zlib stream, so the file decodes anywhere as an ordinary PNG. `threads` as in
// EffectiveThreads (0 = all cores). Throws std::logic_error on another type.
std::string EncodePngFile(const cv::Mat& image, int threads = 0);

}  // namespace openable
