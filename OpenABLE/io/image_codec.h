// Image files as bytes, without OpenCV's imgcodecs for the common cases: recognising PNG, JPEG,
// PGM/PPM and BMP from their first bytes; checking a PNG's chunks and a JPEG's end before
// decoding; decoding PNG with libpng and JPEG with libjpeg in the program; writing PNG with
// libdeflate. imgcodecs brings GDAL, GDCM, OpenEXR and over a hundred other shared libraries
// that every run would load at start-up (docs/benchmarks.md, "Start-up without imgcodecs"),
// while the frames of almost every data set are PNG or JPEG; other formats load imgcodecs on
// first use (module_loader.h). Frame sources (frame_source.h) read files and hand their bytes
// here.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace openable {

// Decodes the common formats: PNG whose chunks are sound (DecodePng) and JPEG with its end
// marker (libjpeg), both in the program, and binary and plain PGM/PPM of 8 or 16 bits and BMP
// through OpenCV's imgcodecs, a module loaded on first use (module_loader.h). The image comes
// as the file stores it (8 or 16 bits; 1, 3 or 4 channels, BGR order); `grey_alpha` is set when
// a PNG is grey + alpha. Returns an empty Mat for anything else, or when the decoder fails, so
// that OpenImageIO decodes the file or says precisely what is wrong with it. Throws InputError
// with the damage found when a PNG is truncated or a chunk's CRC does not match, or a JPEG is
// damaged (libjpeg's first warning), and "is WxH (N megapixels); expected at most 100
// megapixels ..." for a larger PNG or JPEG, before decoding it (docs/robustness.md).
cv::Mat DecodeCommonFormat(const std::vector<unsigned char>& bytes, bool& grey_alpha);

// Decodes the bytes of a PNG file whose chunks are sound (8-bit samples without interlacing
// from the whole zlib stream by libdeflate, anything else by libpng) into 8- or 16-bit
// pixels, grey (grey, grey + alpha) or BGR (colour, palette, colour + alpha); alpha is
// dropped, bit depths 1, 2 and 4 are scaled to 8 bits, no gamma is applied: the pixels
// OpenCV's decoder gives for IMREAD_UNCHANGED once its alpha channel is dropped. Returns false
// with `why` set when libpng refuses the data.
bool DecodePng(const std::vector<unsigned char>& bytes, cv::Mat& image, std::string& why);

// The bytes of a PNG file of `image` (CV_8U or CV_16U; 1 channel grey, 3 BGR, 4 BGRA). Rows go
// through the Sub filter, in bands of rows in parallel, and the whole is compressed by
// libdeflate at level 1 into one zlib stream on one thread (IDAT chunks of 1 MiB). `threads`
// (for the filter) as in EffectiveThreads (0 = all cores). Throws std::logic_error on another
// type.
std::string EncodePngFile(const cv::Mat& image, int threads = 0);

// The bytes of a baseline JPEG file of an 8-bit grey (CV_8UC1) or BGR (CV_8UC3) image at
// `quality` (1-100, libjpeg's scale), with libjpeg: the thumbnails of the HTML report. Throws
// std::logic_error on another type, InputError with libjpeg's message should it fail.
std::string EncodeJpegFile(const cv::Mat& image, int quality = 85);

}  // namespace openable
