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

// ---------------------------------------------------------------------------------------------
// NumPy .npy

// The header of a .npy file is a Python dict literal:
//   {'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }
struct NpyHeader {
  std::string descr;
  bool fortran_order = false;
  std::vector<std::int64_t> shape;
  bool has_descr = false, has_order = false, has_shape = false;
};

class NpyHeaderParser {
 public:
  NpyHeaderParser(std::string_view text, const std::string& where) : s_(text), where_(where) {}

  NpyHeader Parse() {
    NpyHeader h;
    Expect('{');
    while (true) {
      SkipSpace();
      if (Peek() == '}') break;
      const std::string key = String();
      Expect(':');
      SkipSpace();
      if (key == "descr") {
        if (Peek() == '[') Fail("structured dtype (a list of fields) is not supported");
        h.descr = String();
        h.has_descr = true;
      } else if (key == "fortran_order") {
        h.fortran_order = Bool();
        h.has_order = true;
      } else if (key == "shape") {
        h.shape = Tuple();
        h.has_shape = true;
      } else {
        SkipValue();
      }
      SkipSpace();
      if (Peek() == ',') {
        ++i_;
        continue;
      }
      if (Peek() != '}') BadHeader();
      break;
    }
    if (!h.has_descr || !h.has_order || !h.has_shape) {
      Fail("header lacks 'descr', 'fortran_order' or 'shape'");
    }
    return h;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + ": " + what); }
  [[noreturn]] void BadHeader() const { Fail("header is not a valid .npy dict literal"); }

  char Peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void SkipSpace() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  void Expect(char c) {
    SkipSpace();
    if (Peek() != c) BadHeader();
    ++i_;
  }
  std::string String() {
    SkipSpace();
    const char q = Peek();
    if (q != '\'' && q != '"') BadHeader();
    const std::size_t end = s_.find(q, i_ + 1);
    if (end == std::string_view::npos) BadHeader();
    std::string out(s_.substr(i_ + 1, end - i_ - 1));
    i_ = end + 1;
    return out;
  }
  bool Bool() {
    if (s_.substr(i_, 4) == "True") {
      i_ += 4;
      return true;
    }
    if (s_.substr(i_, 5) == "False") {
      i_ += 5;
      return false;
    }
    BadHeader();
    return false;
  }
  std::vector<std::int64_t> Tuple() {
    std::vector<std::int64_t> out;
    Expect('(');
    while (true) {
      SkipSpace();
      if (Peek() == ')') break;
      std::int64_t v = 0;
      const char* begin = s_.data() + i_;
      const auto r = std::from_chars(begin, s_.data() + s_.size(), v);
      if (r.ec != std::errc() || v < 0) BadHeader();
      i_ += static_cast<std::size_t>(r.ptr - begin);
      if (Peek() == 'L') ++i_;  // Python 2 long
      out.push_back(v);
      SkipSpace();
      if (Peek() == ',') {
        ++i_;
      } else if (Peek() != ')') {
        BadHeader();
      }
    }
    ++i_;
    return out;
  }
  // Skips a value of an unknown key: a string, or anything up to the next ',' or '}' at depth 0.
  void SkipValue() {
    if (Peek() == '\'' || Peek() == '"') {
      String();
      return;
    }
    int depth = 0;
    for (; i_ < s_.size(); ++i_) {
      const char c = s_[i_];
      if (c == '(' || c == '[' || c == '{') ++depth;
      if (c == ')' || c == ']' || c == '}') {
        if (depth == 0) return;
        --depth;
      }
      if (c == ',' && depth == 0) return;
    }
  }

  std::string_view s_;
  const std::string& where_;
  std::size_t i_ = 0;
};

// Little-endian unsigned integer of `n` bytes.
std::uint64_t LoadLe(const unsigned char* p, int n) {
  std::uint64_t v = 0;
  for (int k = n - 1; k >= 0; --k) v = (v << 8) | p[k];
  return v;
}

enum class NpyKind { kBool, kU1, kI1, kU2, kI2, kU4, kI4, kU8, kI8, kF4, kF8 };

float ElementAsFloat(NpyKind kind, const unsigned char* p) {
  switch (kind) {
    case NpyKind::kBool:
      return p[0] != 0 ? 1.f : 0.f;
    case NpyKind::kU1:
      return static_cast<float>(p[0]);
    case NpyKind::kI1:
      return static_cast<float>(static_cast<std::int8_t>(p[0]));
    case NpyKind::kU2:
      return static_cast<float>(LoadLe(p, 2));
    case NpyKind::kI2:
      return static_cast<float>(static_cast<std::int16_t>(LoadLe(p, 2)));
    case NpyKind::kU4:
      return static_cast<float>(LoadLe(p, 4));
    case NpyKind::kI4:
      return static_cast<float>(static_cast<std::int32_t>(LoadLe(p, 4)));
    case NpyKind::kU8:
      return static_cast<float>(LoadLe(p, 8));
    case NpyKind::kI8:
      return static_cast<float>(static_cast<std::int64_t>(LoadLe(p, 8)));
    case NpyKind::kF4: {
      const auto bits = static_cast<std::uint32_t>(LoadLe(p, 4));
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    }
    case NpyKind::kF8: {
      const std::uint64_t bits = LoadLe(p, 8);
      double d;
      std::memcpy(&d, &bits, 8);
      return static_cast<float>(d);
    }
  }
  return 0.f;
}

// Kind and item size of a descr such as "<f4" or "|u1"; false when unsupported.
bool ParseDescr(const std::string& descr, NpyKind* kind, int* size) {
  if (descr.size() < 2) return false;
  const char order = descr[0];
  const std::string code = descr.substr(1);
  static const struct {
    const char* code;
    NpyKind kind;
    int size;
  } kTypes[] = {{"b1", NpyKind::kBool, 1}, {"?", NpyKind::kBool, 1}, {"u1", NpyKind::kU1, 1},
                {"i1", NpyKind::kI1, 1},   {"u2", NpyKind::kU2, 2},  {"i2", NpyKind::kI2, 2},
                {"u4", NpyKind::kU4, 4},   {"i4", NpyKind::kI4, 4},  {"u8", NpyKind::kU8, 8},
                {"i8", NpyKind::kI8, 8},   {"f4", NpyKind::kF4, 4},  {"f8", NpyKind::kF8, 8}};
  for (const auto& t : kTypes) {
    if (code != t.code) continue;
    if (order == '<' || (order == '|' && t.size == 1)) {
      *kind = t.kind;
      *size = t.size;
      return true;
    }
    return false;
  }
  return false;
}

std::string ShapeText(const std::vector<std::int64_t>& shape) {
  std::string s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) {
    s += (k ? ", " : "") + std::to_string(shape[k]);
  }
  return s + (shape.size() == 1 ? ",)" : ")");
}

cv::Mat1f ReadNpy(const std::string& path, const std::string& where) {
  const std::string data = ReadWholeFile(path, where);
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  if (data.size() < 10 || data.compare(0, 6, "\x93NUMPY") != 0) {
    throw InputError(where + ": not a NumPy .npy file (no \\x93NUMPY magic at the start)");
  }
  const int major = bytes[6], minor = bytes[7];
  if (major < 1 || major > 3 || minor != 0) {
    throw InputError(where + ": .npy format version " + std::to_string(major) + "." +
                     std::to_string(minor) + " is not supported; expected 1.0, 2.0 or 3.0");
  }
  const std::size_t prefix = major == 1 ? 10 : 12;
  if (data.size() < prefix) throw InputError(where + ": truncated .npy header");
  const std::size_t header_len = LoadLe(bytes + 8, major == 1 ? 2 : 4);
  if (data.size() - prefix < header_len) {
    throw InputError(where + ": truncated .npy header (" + std::to_string(header_len) +
                     " bytes announced, the file has " + std::to_string(data.size()) + ")");
  }
  const NpyHeader h =
      NpyHeaderParser(std::string_view(data).substr(prefix, header_len), where).Parse();

  NpyKind kind{};
  int item = 0;
  if (!ParseDescr(h.descr, &kind, &item)) {
    throw InputError(where + ": dtype " + Quoted(h.descr) +
                     " is not supported; expected bool, u1, i1, u2, i2, u4, i4, u8, i8, f4 or "
                     "f8, little-endian ('<') or '|'");
  }
  if (h.shape.size() != 2) {
    throw InputError(
        where + ": shape " + ShapeText(h.shape) + " has " + std::to_string(h.shape.size()) +
        (h.shape.size() == 1 ? " dimension" : " dimensions") + "; expected 2 (a matrix)");
  }
  const std::int64_t rows = h.shape[0], cols = h.shape[1];
  constexpr std::int64_t kMaxInt = std::numeric_limits<int>::max();
  if (rows > kMaxInt || cols > kMaxInt || (cols > 0 && rows > kMaxInt / cols)) {
    throw InputError(where + ": shape " + ShapeText(h.shape) + " is too large");
  }
  const std::uint64_t count = static_cast<std::uint64_t>(rows) * static_cast<std::uint64_t>(cols);
  const std::uint64_t needed = count * static_cast<std::uint64_t>(item);
  const std::size_t offset = prefix + header_len;
  if (data.size() - offset < needed) {
    throw InputError(where + ": truncated data: " + std::to_string(data.size() - offset) +
                     " bytes, expected " + std::to_string(needed) + " for shape " +
                     ShapeText(h.shape) + " of " + h.descr);
  }
  cv::Mat1f m(static_cast<int>(rows), static_cast<int>(cols));
  const unsigned char* src = bytes + offset;
  for (int r = 0; r < m.rows; ++r) {
    float* out = m[r];
    for (int c = 0; c < m.cols; ++c) {
      const std::uint64_t index = h.fortran_order ? static_cast<std::uint64_t>(c) * rows + r
                                                  : static_cast<std::uint64_t>(r) * cols + c;
      out[c] = ElementAsFloat(kind, src + index * static_cast<std::uint64_t>(item));
    }
  }
  return m;
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

}  // namespace openable
