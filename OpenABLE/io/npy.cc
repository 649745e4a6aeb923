#include "OpenABLE/io/npy.h"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/base/strings.h"

namespace openable {
namespace {

// ---------------------------------------------------------------------------------------------
// NumPy .npy

// The header of a .npy file is a Python dict literal:
//   {'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }
struct NpyHeaderFields {
  std::string descr;
  bool fortran_order = false;
  std::vector<std::int64_t> shape;
  bool has_descr = false, has_order = false, has_shape = false;
};

class NpyHeaderParser {
 public:
  NpyHeaderParser(std::string_view text, const std::string& where) : s_(text), where_(where) {}

  NpyHeaderFields Parse() {
    NpyHeaderFields h;
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
      return static_cast<float>(LittleEndianAt(p, 2));
    case NpyKind::kI2:
      return static_cast<float>(static_cast<std::int16_t>(LittleEndianAt(p, 2)));
    case NpyKind::kU4:
      return static_cast<float>(LittleEndianAt(p, 4));
    case NpyKind::kI4:
      return static_cast<float>(static_cast<std::int32_t>(LittleEndianAt(p, 4)));
    case NpyKind::kU8:
      return static_cast<float>(LittleEndianAt(p, 8));
    case NpyKind::kI8:
      return static_cast<float>(static_cast<std::int64_t>(LittleEndianAt(p, 8)));
    case NpyKind::kF4: {
      const auto bits = static_cast<std::uint32_t>(LittleEndianAt(p, 4));
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    }
    case NpyKind::kF8: {
      const std::uint64_t bits = LittleEndianAt(p, 8);
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

}  // namespace

std::uint64_t LittleEndianAt(const unsigned char* p, int n) {
  std::uint64_t v = 0;
  for (int k = n - 1; k >= 0; --k) v = (v << 8) | p[k];
  return v;
}

std::string NpyShapeText(const std::vector<std::int64_t>& shape) {
  std::string s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) {
    s += (k ? ", " : "") + std::to_string(shape[k]);
  }
  return s + (shape.size() == 1 ? ",)" : ")");
}

std::string NpyHeaderOf(const std::string& descr, const std::string& shape) {
  // The .npy format: magic, version 1.0, a little-endian uint16 header length, then a Python
  // dict literal padded with spaces and ended by '\n' so that the data starts at a multiple
  // of 64 bytes. Written by hand: none of our dependencies writes .npy (OpenCV does not, and
  // Debian packages no C++ NumPy-format library).
  std::string dict = "{'descr': " + descr + ", 'fortran_order': False, 'shape': " + shape + ", }";
  const size_t preamble = 10;  // magic (6) + version (2) + length (2)
  size_t total = preamble + dict.size() + 1;
  const size_t padded = (total + 63) / 64 * 64;
  dict.append(padded - total, ' ');
  dict.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  const auto len = static_cast<std::uint16_t>(dict.size());
  out.push_back(static_cast<char>(len & 0xFF));
  out.push_back(static_cast<char>(len >> 8));
  return out + dict;
}

std::string NpyHeader(int rows, int cols) {
  return NpyHeaderOf("'<f4'", "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")");
}

std::string EncodeNpy(const cv::Mat1f& m) {
  std::string out = NpyHeader(m.rows, m.cols);
  static_assert(sizeof(float) == 4, "float32 expected");
  const size_t bytes = static_cast<size_t>(m.rows) * m.cols * sizeof(float);
  out.reserve(out.size() + bytes);
  for (int i = 0; i < m.rows; ++i)  // x86 and ARM Linux are little-endian, like '<f4'
    out.append(reinterpret_cast<const char*>(m.ptr<float>(i)), m.cols * sizeof(float));
  return out;
}

NpyHeaderInfo ReadNpyHeader(std::string_view data, const std::string& where) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  if (data.size() < 10 || data.substr(0, 6) != std::string_view("\x93NUMPY", 6)) {
    throw InputError(where + ": not a NumPy .npy file (no \\x93NUMPY magic at the start)");
  }
  const int major = bytes[6], minor = bytes[7];
  if (major < 1 || major > 3 || minor != 0) {
    throw InputError(where + ": .npy format version " + std::to_string(major) + "." +
                     std::to_string(minor) + " is not supported; expected 1.0, 2.0 or 3.0");
  }
  const std::size_t prefix = major == 1 ? 10 : 12;
  if (data.size() < prefix) throw InputError(where + ": truncated .npy header");
  const std::size_t header_len = LittleEndianAt(bytes + 8, major == 1 ? 2 : 4);
  if (data.size() - prefix < header_len) {
    throw InputError(where + ": truncated .npy header (" + std::to_string(header_len) +
                     " bytes announced, the file has " + std::to_string(data.size()) + ")");
  }
  NpyHeaderFields fields = NpyHeaderParser(data.substr(prefix, header_len), where).Parse();
  NpyHeaderInfo info;
  info.descr = std::move(fields.descr);
  info.fortran_order = fields.fortran_order;
  info.shape = std::move(fields.shape);
  info.data_offset = prefix + header_len;
  return info;
}

cv::Mat1f DecodeNpyMatrix(std::string_view data, const std::string& where) {
  const NpyHeaderInfo h = ReadNpyHeader(data, where);
  if (h.descr == "|O") {
    throw InputError(where +
                     ": holds Python objects (dtype object, pickled); expected a numeric matrix");
  }
  NpyKind kind{};
  int item = 0;
  if (!ParseDescr(h.descr, &kind, &item)) {
    throw InputError(where + ": dtype " + Quoted(h.descr) +
                     " is not supported; expected bool, u1, i1, u2, i2, u4, i4, u8, i8, f4 or "
                     "f8, little-endian ('<') or '|'");
  }
  if (h.shape.size() != 2) {
    throw InputError(
        where + ": shape " + NpyShapeText(h.shape) + " has " + std::to_string(h.shape.size()) +
        (h.shape.size() == 1 ? " dimension" : " dimensions") + "; expected 2 (a matrix)");
  }
  const std::int64_t rows = h.shape[0], cols = h.shape[1];
  constexpr std::int64_t kMaxInt = std::numeric_limits<int>::max();
  if (rows > kMaxInt || cols > kMaxInt || (cols > 0 && rows > kMaxInt / cols)) {
    throw InputError(where + ": shape " + NpyShapeText(h.shape) + " is too large");
  }
  const std::uint64_t count = static_cast<std::uint64_t>(rows) * static_cast<std::uint64_t>(cols);
  const std::uint64_t needed = count * static_cast<std::uint64_t>(item);
  const std::size_t offset = h.data_offset;
  if (data.size() - offset < needed) {
    throw InputError(where + ": truncated data: " + std::to_string(data.size() - offset) +
                     " bytes, expected " + std::to_string(needed) + " for shape " +
                     NpyShapeText(h.shape) + " of " + h.descr);
  }
  cv::Mat1f m(static_cast<int>(rows), static_cast<int>(cols));
  const auto* src = reinterpret_cast<const unsigned char*>(data.data()) + offset;
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

}  // namespace openable
