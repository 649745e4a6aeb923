#include "OpenABLE/evaluation/matrix_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <opencv2/imgcodecs.hpp>  // the IMREAD_ flags only
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/module_loader.h"
#include "OpenABLE/base/strings.h"
#include "OpenABLE/evaluation/text_parsing.h"
#include "OpenABLE/io/module_api.h"
#include "OpenABLE/io/npy.h"

namespace openable {
namespace {

using evaluation_internal::IsBlank;
using evaluation_internal::ParseNumber;
using evaluation_internal::ReadWholeFile;
using evaluation_internal::RequireFile;

namespace fs = std::filesystem;

// Lower-case extension without the dot ("" when none).
std::string ExtensionOf(const std::string& path) {
  std::string e = Lower(fs::path(path).extension().string());
  if (!e.empty() && e.front() == '.') e.erase(0, 1);
  return e;
}

bool IsTextExtension(const std::string& e) { return e == "txt" || e == "csv" || e == "dat"; }

bool IsImageExtension(const std::string& e) {
  static const char* const kImage[] = {"png", "bmp",  "dib", "pgm",  "ppm", "pbm",  "pnm",
                                       "pxm", "pfm",  "tif", "tiff", "jpg", "jpeg", "jpe",
                                       "jp2", "webp", "sr",  "ras",  "exr", "hdr",  "pic"};
  return std::find(std::begin(kImage), std::end(kImage), e) != std::end(kImage);
}

// ---------------------------------------------------------------------------------------------
// Text

cv::Mat1f ReadText(const std::string& path, const std::string& where) {
  const std::string data = ReadWholeFile(path, where);
  std::size_t pos = data.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // UTF-8 BOM
  std::vector<float> values;
  int cols = -1;
  int first_row_line = 0;
  int rows = 0;
  int line_number = 0;
  while (pos < data.size()) {
    std::size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    ++line_number;
    std::string_view line(data.data() + pos, end - pos);
    pos = end + 1;
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);

    const std::string at = where + ":" + std::to_string(line_number);
    int count = 0;
    std::size_t i = 0;
    bool after_comma = false;  // a comma was read since the last value
    while (true) {
      while (i < line.size() && IsBlank(line[i])) ++i;
      if (i == line.size()) break;
      if (line[i] == ',') {
        if (count == 0 || after_comma) {
          throw InputError(at + ": empty value in column " + std::to_string(count + 1) +
                           "; expected a number");
        }
        after_comma = true;
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < line.size() && !IsBlank(line[j]) && line[j] != ',') ++j;
      const std::string_view token = line.substr(i, j - i);
      double v = 0.0;
      if (!ParseNumber(token, &v)) {
        throw InputError(at + ": value " + Quoted(token) + " in column " +
                         std::to_string(count + 1) + " is not a number");
      }
      values.push_back(static_cast<float>(v));
      ++count;
      after_comma = false;
      i = j;
    }
    if (count == 0) continue;  // blank or comment line
    if (cols == -1) {
      cols = count;
      first_row_line = line_number;
    } else if (count != cols) {
      throw InputError(at + ": row has " + std::to_string(count) + " values, expected " +
                       std::to_string(cols) + " like the first row (line " +
                       std::to_string(first_row_line) + ")");
    }
    if (rows == std::numeric_limits<int>::max()) throw InputError(where + ": too many rows");
    ++rows;
  }
  if (rows == 0) throw InputError(where + ": no rows; expected one row of numbers per line");
  cv::Mat1f m(rows, cols);
  std::copy(values.begin(), values.end(), m.begin());
  return m;
}

cv::Mat1f ReadNpy(const std::string& path, const std::string& where) {
  return DecodeNpyMatrix(ReadWholeFile(path, where), where);
}

// ---------------------------------------------------------------------------------------------
// Images

cv::Mat1f ReadImage(const std::string& path, const std::string& where) {
  // OpenCV's imgcodecs, loaded on first use (base/module_loader.h).
  cv::Mat image;
  reinterpret_cast<OpenableCodecsRead>(ModuleSymbol("codecs", "openable_codecs_read"))(
      path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION, image);
  if (image.empty()) {
    throw InputError(where +
                     ": cannot be decoded as an image; expected an image OpenCV reads "
                     "(PNG, BMP, PGM, TIFF, ...)");
  }
  cv::Mat1f m;
  image.convertTo(m, CV_32F);
  return m;
}

}  // namespace

cv::Mat1f ReadMatrixFile(const std::string& path) {
  const std::string where = "matrix file " + Quoted(path);
  RequireFile(path, where);
  const std::string ext = ExtensionOf(path);
  if (ext == "npy") return ReadNpy(path, where);
  if (IsTextExtension(ext)) return ReadText(path, where);
  if (IsImageExtension(ext)) return ReadImage(path, where);
  const std::string what =
      ext.empty() ? "has no extension" : "extension ." + ext + " is not supported";
  throw InputError(where + ": " + what +
                   "; expected .npy, .txt/.csv/.dat (text) or an image (.png, .bmp, .pgm, .tif, "
                   "...)");
}

cv::Size MatrixFileSize(const std::string& path) {
  if (ExtensionOf(path) == "npy") {
    // NumPy's headers are a few hundred bytes; a 2-D one read from the first 64 KiB gives the
    // size. Anything else is left to the whole read and its messages.
    std::ifstream in(path, std::ios::binary);
    std::string head(65536, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(std::max<std::streamsize>(0, in.gcount())));
    try {
      const NpyHeaderInfo header = ReadNpyHeader(head, path);
      if (header.shape.size() == 2 && header.shape[0] > 0 && header.shape[1] > 0 &&
          header.shape[0] <= std::numeric_limits<int>::max() &&
          header.shape[1] <= std::numeric_limits<int>::max())
        return cv::Size(static_cast<int>(header.shape[1]), static_cast<int>(header.shape[0]));
    } catch (const InputError&) {
    }
  }
  return ReadMatrixFile(path).size();
}

}  // namespace openable
