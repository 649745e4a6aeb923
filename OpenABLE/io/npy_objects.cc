#include "OpenABLE/io/npy_objects.h"

#include <libdeflate.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/npy.h"

namespace openable {
namespace {

using Value = std::shared_ptr<PyValue>;
using Kind = PyValue::Kind;

// ---------------------------------------------------------------------------------------------
// Values

// Makes the leaves of what is read. None, False, True and the integers -1..255 are made once
// and shared, so that a large boolean or small-integer array costs a pointer an element.
class LeafValues {
 public:
  LeafValues() : none_(std::make_shared<PyValue>()) {
    false_ = Make(Kind::kBool, 0);
    true_ = Make(Kind::kBool, 1);
    for (std::int64_t v = kSmallest; v <= kLargest; ++v) small_.push_back(Make(Kind::kInt, v));
  }
  Value None() const { return none_; }
  Value Bool(bool b) const { return b ? true_ : false_; }
  Value Int(std::int64_t v) const {
    if (v >= kSmallest && v <= kLargest) return small_[static_cast<std::size_t>(v - kSmallest)];
    return Make(Kind::kInt, v);
  }
  static Value Float(double v) {
    auto value = std::make_shared<PyValue>();
    value->kind = Kind::kFloat;
    value->real = v;
    return value;
  }
  // kText or kBytes.
  static Value String(Kind kind, std::string text) {
    auto value = std::make_shared<PyValue>();
    value->kind = kind;
    value->text = std::move(text);
    return value;
  }

 private:
  static constexpr std::int64_t kSmallest = -1, kLargest = 255;
  static Value Make(Kind kind, std::int64_t v) {
    auto value = std::make_shared<PyValue>();
    value->kind = kind;
    value->integer = v;
    return value;
  }
  Value none_, false_, true_;
  std::vector<Value> small_;
};

// "a list", "an int", ... for messages.
std::string KindName(Kind kind) {
  switch (kind) {
    case Kind::kNone:
      return "None";
    case Kind::kBool:
      return "a bool";
    case Kind::kInt:
      return "an int";
    case Kind::kFloat:
      return "a float";
    case Kind::kText:
      return "a string";
    case Kind::kBytes:
      return "a bytes object";
    case Kind::kList:
      return "a list";
    case Kind::kTuple:
      return "a tuple";
    case Kind::kDict:
      return "a dict";
    case Kind::kArray:
      return "a NumPy array";
  }
  return "a value";
}

bool IsString(const PyValue& v) { return v.kind == Kind::kText || v.kind == Kind::kBytes; }

// Appends code point `c` (at most U+10FFFF) as UTF-8.
void AppendUtf8(std::uint32_t c, std::string& out) {
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xc0 | (c >> 6));
    out += static_cast<char>(0x80 | (c & 0x3f));
  } else if (c < 0x10000) {
    out += static_cast<char>(0xe0 | (c >> 12));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3f));
    out += static_cast<char>(0x80 | (c & 0x3f));
  } else {
    out += static_cast<char>(0xf0 | (c >> 18));
    out += static_cast<char>(0x80 | ((c >> 12) & 0x3f));
    out += static_cast<char>(0x80 | ((c >> 6) & 0x3f));
    out += static_cast<char>(0x80 | (c & 0x3f));
  }
}

// The latin-1 bytes of UTF-8 `text`; false when it is not UTF-8 or holds a character above
// U+00FF. Python 3 pickles bytes for protocols 0-2 as _codecs.encode(<latin-1 text>, 'latin1').
bool Latin1FromUtf8(std::string_view text, std::string& out) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else if ((c == 0xc2 || c == 0xc3) && i + 1 < text.size() &&
               (static_cast<unsigned char>(text[i + 1]) & 0xc0) == 0x80) {
      out +=
          static_cast<char>(((c & 0x03) << 6) | (static_cast<unsigned char>(text[i + 1]) & 0x3f));
      ++i;
    } else {
      return false;
    }
  }
  return true;
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The text of a protocol 0 UNICODE argument ("raw-unicode-escape": bytes are latin-1 code
// points, \uXXXX and \UXXXXXXXX escape the others) as UTF-8; false on a malformed escape or
// a code point that is no Unicode scalar value.
bool RawUnicodeEscapeToUtf8(std::string_view s, std::string& out) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '\\' && i + 1 < s.size() && (s[i + 1] == 'u' || s[i + 1] == 'U')) {
      const std::size_t digits = s[i + 1] == 'u' ? 4 : 8;
      if (s.size() - i - 2 < digits) return false;
      std::uint32_t code = 0;
      for (std::size_t k = 0; k < digits; ++k) {
        const int d = HexDigit(s[i + 2 + k]);
        if (d < 0 || code > 0x10ffff) return false;
        code = code * 16 + static_cast<std::uint32_t>(d);
      }
      if (code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return false;
      AppendUtf8(code, out);
      i += 1 + digits;
    } else {
      AppendUtf8(c, out);
    }
  }
  return true;
}

// The bytes of a protocol 0 STRING argument: a Python 2 string literal between matching quotes,
// its escapes decoded as Python's codecs.escape_decode does; false when it is malformed.
bool PythonStringLiteral(std::string_view line, std::string& out) {
  if (line.size() < 2 || line.front() != line.back() || (line[0] != '\'' && line[0] != '"')) {
    return false;
  }
  const std::string_view s = line.substr(1, line.size() - 2);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '\\') {
      out += s[i];
      continue;
    }
    if (++i == s.size()) return false;  // a trailing backslash
    const char c = s[i];
    static const char kSimple[] = "\\\\''\"\"a\ab\bf\fn\nr\rt\tv\v";
    const char* simple = nullptr;
    for (const char* p = kSimple; *p != '\0'; p += 2) {
      if (*p == c) simple = p;
    }
    if (simple != nullptr) {
      out += simple[1];
    } else if (c == '\n') {
      // A backslash before a new line continues the literal.
    } else if (c == 'x') {
      if (s.size() - i < 3 || HexDigit(s[i + 1]) < 0 || HexDigit(s[i + 2]) < 0) return false;
      out += static_cast<char>(HexDigit(s[i + 1]) * 16 + HexDigit(s[i + 2]));
      i += 2;
    } else if (c >= '0' && c <= '7') {
      int code = 0, digits = 0;
      for (; digits < 3 && i < s.size() && s[i] >= '0' && s[i] <= '7'; ++digits, ++i) {
        code = code * 8 + (s[i] - '0');
      }
      --i;
      out += static_cast<char>(code & 0xff);
    } else {
      out += '\\';  // Python keeps unknown escapes as they are
      out += c;
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
// NumPy dtypes and numeric data

// A dtype the reader converts: kind 'b' (bool), 'i', 'u', 'f' or 'O' (object), the item size in
// bytes, and the byte order: '<', '>', '|' (not applicable) or '=' (native: little-endian on
// the machines OpenABLE runs on).
struct NumpyDtype {
  char kind = 'O';
  int size = 8;
  char order = '|';
};

// The dtype of `name` as dtype.__reduce__ and .npy headers write it after the byte order:
// "b1", "i8", "u2", "f4", "O8"; false when the reader does not convert that dtype.
bool DtypeFromName(std::string_view name, char order, NumpyDtype& out) {
  if (name == "?") name = "b1";
  if (name.empty()) return false;
  const char kind = name[0];
  int size = 0;
  const std::string_view digits = name.substr(1);
  if (!digits.empty()) {
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), size);
    if (r.ec != std::errc() || r.ptr != digits.data() + digits.size()) return false;
  }
  bool known = false;
  switch (kind) {
    case 'O':
      known = true;
      size = 8;
      break;
    case 'b':
      known = size == 1;
      break;
    case 'i':
    case 'u':
      known = size == 1 || size == 2 || size == 4 || size == 8;
      break;
    case 'f':
      known = size == 4 || size == 8;
      break;
    default:
      break;
  }
  if (!known) return false;
  out.kind = kind;
  out.size = size;
  out.order = order;
  return true;
}

const char kDtypesRead[] =
    "expected bool (b1), i1, u1, i2, u2, i4, u4, i8, u8, f4, f8 or object (O)";

// The number of elements of `shape`; throws when a dimension is negative or the product passes
// 2^62 (every element of the arrays read takes a byte or more of the file).
std::uint64_t ElementCount(const std::vector<std::int64_t>& shape, const std::string& where) {
  std::uint64_t count = 1;
  bool empty = false;
  for (const std::int64_t d : shape) {
    if (d < 0)
      throw InputError(where + ": shape " + NpyShapeText(shape) + " has a negative dimension");
    if (d == 0) empty = true;
  }
  if (empty) return 0;
  for (const std::int64_t d : shape) {
    if (count > (std::uint64_t{1} << 62) / static_cast<std::uint64_t>(d)) {
      throw InputError(where + ": shape " + NpyShapeText(shape) + " is too large");
    }
    count *= static_cast<std::uint64_t>(d);
  }
  return count;
}

void CheckByteOrder(const NumpyDtype& d, const std::string& where) {
  if (d.order == '>' && d.size > 1) {
    const std::string name = ">" + std::string(1, d.kind) + std::to_string(d.size);
    throw InputError(where + ": big-endian data (dtype '" + name +
                     "') are not read; save the array little-endian, e.g. a.astype('<" +
                     name.substr(1) + "')");
  }
}

// The value of the element at `p` (little-endian, or one byte).
Value ElementValue(const NumpyDtype& d, const unsigned char* p, const LeafValues& leaves,
                   const std::string& where) {
  const std::uint64_t bits = LittleEndianAt(p, d.size);
  switch (d.kind) {
    case 'b':
      return leaves.Bool(bits != 0);
    case 'i': {
      const int shift = 64 - 8 * d.size;  // sign-extends the item
      return leaves.Int(static_cast<std::int64_t>(bits << shift) >> shift);
    }
    case 'u':
      if (bits > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
        throw InputError(where + ": the uint64 value " + std::to_string(bits) +
                         " does not fit a signed 64-bit integer");
      }
      return leaves.Int(static_cast<std::int64_t>(bits));
    case 'f':
      if (d.size == 4) {
        const auto bits32 = static_cast<std::uint32_t>(bits);
        float f;
        std::memcpy(&f, &bits32, sizeof f);
        return LeafValues::Float(f);
      } else {
        double f;
        std::memcpy(&f, &bits, sizeof f);
        return LeafValues::Float(f);
      }
    default:
      break;
  }
  throw std::logic_error("ElementValue: not a numeric dtype");
}

// The elements, in C order, of a numeric array of `shape` whose `data` hold them in C order, or
// in Fortran order when `fortran`.
std::vector<Value> NumericElements(const NumpyDtype& d, const std::vector<std::int64_t>& shape,
                                   bool fortran, std::string_view data, const LeafValues& leaves,
                                   const std::string& where) {
  CheckByteOrder(d, where);
  const std::uint64_t count = ElementCount(shape, where);
  const auto size = static_cast<std::uint64_t>(d.size);
  if (count > data.size() / size || data.size() != count * size) {
    throw InputError(where + ": array data of " + std::to_string(data.size()) +
                     " bytes do not match shape " + NpyShapeText(shape) + " of " +
                     std::string(1, d.kind) + std::to_string(d.size) + " (" +
                     std::to_string(count) + " elements)");
  }
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  std::vector<Value> items;
  items.reserve(count);
  if (!fortran || shape.size() < 2) {
    for (std::uint64_t e = 0; e < count; ++e) {
      items.push_back(ElementValue(d, bytes + e * size, leaves, where));
    }
    return items;
  }
  // Fortran order: the element at index (i0, i1, ...) is at i0 + s0 * (i1 + s1 * (...)).
  const std::size_t dims = shape.size();
  std::vector<std::uint64_t> stride(dims);
  for (std::size_t k = 0, s = 1; k < dims; s *= static_cast<std::size_t>(shape[k]), ++k) {
    stride[k] = s;
  }
  std::vector<std::int64_t> index(dims, 0);
  std::uint64_t offset = 0;
  for (std::uint64_t e = 0; e < count; ++e) {
    items.push_back(ElementValue(d, bytes + offset * size, leaves, where));
    for (std::size_t k = dims; k-- > 0;) {  // the next index in C order
      offset += stride[k];
      if (++index[k] < shape[k]) break;
      offset -= stride[k] * static_cast<std::uint64_t>(shape[k]);
      index[k] = 0;
    }
  }
  return items;
}

// ---------------------------------------------------------------------------------------------
// Pickles

// The opcodes of protocols 0 and 1, and BINBYTES and SHORT_BINBYTES of protocol 3, are
// printable characters: each entry is the character, then the opcode's name (pickletools').
constexpr std::string_view kPickleLowOpcodes =
    "(MARK )EMPTY_TUPLE .STOP 0POP 1POP_MARK 2DUP BBINBYTES CSHORT_BINBYTES FFLOAT GBINFLOAT IINT "
    "JBININT KBININT1 LLONG MBININT2 NNONE PPERSID QBINPERSID RREDUCE SSTRING TBINSTRING "
    "USHORT_BINSTRING VUNICODE XBINUNICODE ]EMPTY_LIST aAPPEND bBUILD cGLOBAL dDICT eAPPENDS gGET "
    "hBINGET iINST jLONG_BINGET lLIST oOBJ pPUT qBINPUT rLONG_BINPUT sSETITEM tTUPLE uSETITEMS "
    "}EMPTY_DICT";
// Those of protocols 2, 4 and 5 are 0x80, 0x81, ... in this order.
constexpr std::string_view kPickleHighOpcodes =
    "PROTO NEWOBJ EXT1 EXT2 EXT4 TUPLE1 TUPLE2 TUPLE3 NEWTRUE NEWFALSE LONG1 LONG4 "
    "SHORT_BINUNICODE BINUNICODE8 BINBYTES8 EMPTY_SET ADDITEMS FROZENSET NEWOBJ_EX STACK_GLOBAL "
    "MEMOIZE FRAME BYTEARRAY8 NEXT_BUFFER READONLY_BUFFER";

// The name of pickle opcode `op`, or "" when there is none.
std::string PickleOpName(unsigned char op) {
  const bool low = op < 0x80;
  const std::string_view table = low ? kPickleLowOpcodes : kPickleHighOpcodes;
  std::size_t start = 0;
  for (unsigned k = 0; start < table.size(); ++k) {
    const std::size_t end = std::min(table.find(' ', start), table.size());
    const std::string_view entry = table.substr(start, end - start);
    if (low && entry[0] == static_cast<char>(op)) return std::string(entry.substr(1));
    if (!low && k == op - 0x80u) return std::string(entry);
    start = end + 1;
  }
  return "";
}

// The callables a pickle may name.
enum class Callable {
  kReconstruct,  // numpy.core.multiarray._reconstruct(ndarray, shape, typecode): an empty array
  kNdarray,      // numpy.ndarray: _reconstruct's first argument
  kDtype,        // numpy.dtype(name, align, copy)
  kScalar,       // numpy.core.multiarray.scalar(dtype, bytes): a NumPy number
  kFromBuffer,   // numpy.core.numeric._frombuffer(bytes, dtype, shape, order): protocol 5 arrays
  kEncode,       // _codecs.encode(text, 'latin1'): bytes in Python 3 pickles of protocols 0-2
  kRange,        // builtins.range / __builtin__.xrange(start, stop, step)
  kBytes,        // builtins.bytes(): empty bytes in Python 3 pickles of protocols 0-2
};

// A callable or a dtype: the objects of a pickle that are not data.
struct PickleSpecial {
  Value self;  // keeps the object, whose address is the key, alive
  std::string name;
  bool is_dtype = false;
  Callable callable = Callable::kReconstruct;
  NumpyDtype dtype;
};

// A pickle interpreter that runs no code: it knows the opcodes plain data use and the
// constructors of Callable, and refuses anything else (pickletools documents the opcodes).
// Values live behind shared pointers, as Python's objects do: APPENDS on a list fetched from
// the memo changes it wherever it is referred to.
class PickleMachine {
 public:
  PickleMachine(std::string_view pickle, const std::string& where, const NpyObjectLimits& limits)
      : s_(pickle), where_(where), limits_(limits) {}
  PickleMachine(const PickleMachine&) = delete;
  PickleMachine& operator=(const PickleMachine&) = delete;

  // Empties every list, tuple, dict and array the result does not hold (all of them when
  // reading failed) before they are freed: a chain of nested lists as long as the file is then
  // freed without a recursion as deep, and lists that hold themselves are freed too.
  ~PickleMachine() {
    for (const Value& v : containers_) {
      if (!succeeded_ || unfolded_.count(v.get()) == 0) v->items.clear();
    }
  }

  // Runs the pickle to STOP; returns the array it makes, checked (Check).
  Value Run() {
    while (true) {
      if (pos_ >= s_.size()) {
        throw InputError(where_ + ": truncated pickle at byte " + std::to_string(pos_) +
                         " (it ends before its STOP opcode)");
      }
      op_at_ = pos_;
      op_ = static_cast<unsigned char>(s_[pos_++]);
      if (op_ == '.') break;
      Step();
    }
    const Value result = Pop();
    if (result->kind != Kind::kArray || pending_.count(result.get()) != 0) {
      throw InputError(where_ + ": the pickle holds " + Describe(*result) + ", not a NumPy array");
    }
    Check(*result, 0);
    succeeded_ = true;
    return result;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + ": " + what); }
  // "APPEND at byte 12", naming the opcode being run.
  std::string Here() const { return PickleOpName(op_) + " at byte " + std::to_string(op_at_); }
  [[noreturn]] void Truncated() const {
    Fail("truncated pickle at byte " + std::to_string(op_at_) + " (" + PickleOpName(op_) +
         " runs past the end of the file)");
  }

  // Reading the opcodes' arguments.
  const unsigned char* Take(std::uint64_t n) {
    if (n > s_.size() - pos_) Truncated();
    const auto* p = reinterpret_cast<const unsigned char*>(s_.data()) + pos_;
    pos_ += static_cast<std::size_t>(n);
    return p;
  }
  std::uint64_t TakeLittleEndian(int n) { return LittleEndianAt(Take(n), n); }
  std::string_view TakeBytes(std::uint64_t n) {
    const auto* p = Take(n);
    return std::string_view(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n));
  }
  // Protocol 0 arguments: text up to a new line.
  std::string_view TakeLine() {
    const std::size_t end = s_.find('\n', pos_);
    if (end == std::string_view::npos) Truncated();
    const std::string_view line = s_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return line;
  }
  std::int64_t LineInteger(std::string_view line) {
    const std::string_view digits = !line.empty() && line[0] == '+' ? line.substr(1) : line;
    std::int64_t v = 0;
    const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size()) {
      Fail(Here() + ": " + Quoted(line) + " is not an integer that fits 64 bits");
    }
    return v;
  }
  // A two's complement little-endian integer (LONG1, LONG4).
  std::int64_t LongValue(std::string_view bytes) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
    const std::size_t n = bytes.size();
    if (n == 0) return 0;
    const bool negative = (p[n - 1] & 0x80) != 0;
    const unsigned char extension = negative ? 0xff : 0x00;
    for (std::size_t k = 8; k < n; ++k) {
      if (p[k] != extension) Fail(Here() + ": the integer does not fit 64 bits");
    }
    if (n > 8 && ((p[7] & 0x80) != 0) != negative) {
      Fail(Here() + ": the integer does not fit 64 bits");
    }
    const int used = static_cast<int>(std::min<std::size_t>(n, 8));
    std::uint64_t v = LittleEndianAt(p, used);
    if (used < 8 && negative) v |= ~std::uint64_t{0} << (8 * used);
    return static_cast<std::int64_t>(v);
  }
  std::uint64_t Length(std::uint64_t n) {
    if (n > s_.size() - pos_) Truncated();
    return n;
  }

  // The stack. MARK records where the items of the next TUPLE, LIST, APPENDS, ... begin.
  std::size_t Base() const { return marks_.empty() ? 0 : marks_.back(); }
  void Push(Value v) { stack_.push_back(std::move(v)); }
  Value Pop() {
    if (stack_.size() <= Base()) Fail(Here() + " finds the stack empty");
    Value v = std::move(stack_.back());
    stack_.pop_back();
    return v;
  }
  const Value& Top() const {
    if (stack_.size() <= Base()) Fail(Here() + " finds the stack empty");
    return stack_.back();
  }
  std::vector<Value> PopMark() {
    if (marks_.empty()) Fail(Here() + " finds no MARK");
    const auto begin = stack_.begin() + static_cast<std::ptrdiff_t>(marks_.back());
    std::vector<Value> items(std::make_move_iterator(begin), std::make_move_iterator(stack_.end()));
    stack_.erase(begin, stack_.end());
    marks_.pop_back();
    return items;
  }

  Value NewContainer(Kind kind, std::vector<Value> items = {}) {
    auto v = std::make_shared<PyValue>();
    v->kind = kind;
    v->items = std::move(items);
    containers_.push_back(v);
    return v;
  }
  PickleSpecial& NewSpecial(const std::string& name) {
    auto v = std::make_shared<PyValue>();
    PickleSpecial& s = specials_[v.get()];
    s.self = v;
    s.name = name;
    return s;
  }
  PickleSpecial* SpecialOf(const PyValue& v) {
    if (v.kind != Kind::kNone) return nullptr;
    const auto it = specials_.find(&v);
    return it == specials_.end() ? nullptr : &it->second;
  }
  std::string Describe(const PyValue& v) {
    if (const PickleSpecial* s = SpecialOf(v)) {
      return s->is_dtype ? "a numpy.dtype" : s->name;
    }
    if (v.kind == Kind::kArray && pending_.count(&v) != 0) return "an unfinished NumPy array";
    return KindName(v.kind);
  }
  std::string TextOf(const PyValue& v, const char* what) {
    if (!IsString(v)) Fail(Here() + ": " + what + " is " + Describe(v) + ", not a string");
    return v.text;
  }
  std::int64_t IntegerOf(const PyValue& v, const char* what) {
    if (v.kind != Kind::kInt && v.kind != Kind::kBool) {
      Fail(Here() + ": " + what + " is " + Describe(v) + ", not an integer");
    }
    return v.integer;
  }
  PickleSpecial& DtypeOf(const PyValue& v, const char* what) {
    PickleSpecial* s = SpecialOf(v);
    if (s == nullptr || !s->is_dtype) {
      Fail(Here() + ": " + what + " is " + Describe(v) + ", not a numpy.dtype");
    }
    return *s;
  }
  std::vector<std::int64_t> ShapeOf(const PyValue& v) {
    if (v.kind != Kind::kTuple && v.kind != Kind::kList) {
      Fail(Here() + ": the shape is " + Describe(v) + ", not a tuple");
    }
    std::vector<std::int64_t> shape;
    for (const Value& d : v.items) {
      shape.push_back(IntegerOf(*d, "a dimension of the shape"));
      if (shape.back() < 0) Fail(Here() + ": the shape has a negative dimension");
    }
    return shape;
  }
  // Counts `n` more numbers made by range objects (`range` true) or elements of arrays,
  // before they are made, against their limit and the caller's.
  void CountItems(std::uint64_t n, bool range) {
    std::int64_t& made = range ? range_numbers_ : object_items_;
    const std::int64_t limit = std::max<std::int64_t>(
        0, std::min(range ? kNpyMaxRangeNumbers : kNpyMaxObjectItems, limits_.values));
    if (n > static_cast<std::uint64_t>(limit - made)) {
      // made + n may pass 2^63: said as two terms then.
      const std::string total =
          made == 0 ? std::to_string(n) : std::to_string(made) + " + " + std::to_string(n);
      Fail(Here() + (range ? ": the range objects make " : ": the arrays hold ") + total +
           (range ? " numbers" : " elements") + " in all; expected at most " +
           std::to_string(limit) + Why());
    }
    made += static_cast<std::int64_t>(n);
  }
  // " (why)" of the caller's limit, or "".
  std::string Why() const {
    return limits_.expected.empty() ? std::string() : " (" + limits_.expected + ")";
  }

  void Step();
  bool StackStep();
  bool NumberStep();
  bool StringStep();
  bool SequenceStep();
  bool DictStep();
  bool MemoStep();
  bool CallStep();
  [[noreturn]] void RefuseOpcode() const;
  void Global(std::string_view module, std::string_view name);
  Value Call(const PyValue& f, const PyValue& args);
  Value Range(const std::vector<Value>& args);
  void Build(const Value& object, const PyValue& state);
  void BuildArray(PyValue& array, const PyValue& state);
  std::uint64_t Check(const PyValue& v, int depth);

  std::string_view s_;
  const std::string& where_;
  const NpyObjectLimits& limits_;
  std::size_t pos_ = 0, op_at_ = 0;
  unsigned char op_ = 0;
  LeafValues leaves_;
  std::vector<Value> stack_;
  std::vector<std::size_t> marks_;
  std::unordered_map<std::uint64_t, Value> memo_;
  std::vector<Value> containers_;  // every list, tuple, dict and array made
  std::unordered_map<const PyValue*, PickleSpecial> specials_;
  std::unordered_set<const PyValue*> pending_;  // arrays made by _reconstruct, not yet built
  std::int64_t range_numbers_ = 0, object_items_ = 0;
  // The containers the result holds, with the number of values each unfolds into (Check).
  std::unordered_map<const PyValue*, std::uint64_t> unfolded_;
  bool succeeded_ = false;
};

// One opcode. Each family of opcodes has its function, which returns false for an opcode of
// another family; an opcode of none is refused.
void PickleMachine::Step() {
  if (!StackStep() && !NumberStep() && !StringStep() && !SequenceStep() && !DictStep() &&
      !MemoStep() && !CallStep()) {
    RefuseOpcode();
  }
}

// Protocol, framing and the stack: PROTO, FRAME, MARK, POP, POP_MARK, DUP.
bool PickleMachine::StackStep() {
  switch (op_) {
    case 0x80: {  // PROTO
      const unsigned protocol = *Take(1);
      if (protocol > 5) Fail("pickle protocol " + std::to_string(protocol) + " is not read (0-5)");
      return true;
    }
    case 0x95:  // FRAME: a length, then opcodes read as any others
      Length(TakeLittleEndian(8));
      return true;
    case '(':  // MARK
      marks_.push_back(stack_.size());
      return true;
    case '0':  // POP: an item, or the mark when there is none above it
      if (stack_.size() > Base()) {
        stack_.pop_back();
      } else if (!marks_.empty()) {
        marks_.pop_back();
      } else {
        Fail(Here() + " finds the stack empty");
      }
      return true;
    case '1':  // POP_MARK
      PopMark();
      return true;
    case '2':  // DUP
      Push(Top());
      return true;
    default:
      return false;
  }
}

// None, booleans, integers and floats.
bool PickleMachine::NumberStep() {
  switch (op_) {
    case 'N':  // NONE
      Push(leaves_.None());
      return true;
    case 0x88:  // NEWTRUE
      Push(leaves_.Bool(true));
      return true;
    case 0x89:  // NEWFALSE
      Push(leaves_.Bool(false));
      return true;
    case 'I': {  // INT
      const std::string_view line = TakeLine();
      if (line == "01" || line == "00") {
        Push(leaves_.Bool(line == "01"));
      } else {
        Push(leaves_.Int(LineInteger(line)));
      }
      return true;
    }
    case 'J':  // BININT
      Push(leaves_.Int(static_cast<std::int32_t>(TakeLittleEndian(4))));
      return true;
    case 'K':  // BININT1
      Push(leaves_.Int(static_cast<std::int64_t>(TakeLittleEndian(1))));
      return true;
    case 'M':  // BININT2
      Push(leaves_.Int(static_cast<std::int64_t>(TakeLittleEndian(2))));
      return true;
    case 'L': {  // LONG
      std::string_view line = TakeLine();
      if (!line.empty() && line.back() == 'L') line.remove_suffix(1);
      Push(leaves_.Int(LineInteger(line)));
      return true;
    }
    case 0x8a:  // LONG1
      Push(leaves_.Int(LongValue(TakeBytes(TakeLittleEndian(1)))));
      return true;
    case 0x8b: {  // LONG4
      const auto n = static_cast<std::int32_t>(TakeLittleEndian(4));
      if (n < 0) Fail(Here() + ": negative length");
      Push(leaves_.Int(LongValue(TakeBytes(static_cast<std::uint64_t>(n)))));
      return true;
    }
    case 'F': {  // FLOAT
      const std::string_view line = TakeLine();
      double v = 0;
      const auto r = std::from_chars(line.data(), line.data() + line.size(), v);
      if (line.empty() || r.ec != std::errc() || r.ptr != line.data() + line.size()) {
        Fail(Here() + ": " + Quoted(line) + " is not a number");
      }
      Push(LeafValues::Float(v));
      return true;
    }
    case 'G': {  // BINFLOAT: a big-endian IEEE 754 double
      const unsigned char* p = Take(8);
      std::uint64_t bits = 0;
      for (int k = 0; k < 8; ++k) bits = (bits << 8) | p[k];
      double v;
      std::memcpy(&v, &bits, sizeof v);
      Push(LeafValues::Float(v));
      return true;
    }
    default:
      return false;
  }
}

// Bytes (Python 2 strings among them) and text.
bool PickleMachine::StringStep() {
  switch (op_) {
    case 'S': {  // STRING (Python 2 strings are bytes)
      const std::string_view line = TakeLine();
      std::string bytes;
      if (!PythonStringLiteral(line, bytes)) {
        Fail(Here() + ": " + Quoted(line) + " is not a Python string literal");
      }
      Push(LeafValues::String(Kind::kBytes, std::move(bytes)));
      return true;
    }
    case 'T': {  // BINSTRING
      const auto n = static_cast<std::int32_t>(TakeLittleEndian(4));
      if (n < 0) Fail(Here() + ": negative length");
      Push(LeafValues::String(Kind::kBytes, std::string(TakeBytes(static_cast<std::uint64_t>(n)))));
      return true;
    }
    case 'U':  // SHORT_BINSTRING
    case 'C':  // SHORT_BINBYTES
      Push(LeafValues::String(Kind::kBytes, std::string(TakeBytes(TakeLittleEndian(1)))));
      return true;
    case 'B':  // BINBYTES
      Push(LeafValues::String(Kind::kBytes, std::string(TakeBytes(TakeLittleEndian(4)))));
      return true;
    case 0x8e:  // BINBYTES8
    case 0x96:  // BYTEARRAY8: a bytearray, read as bytes
      Push(LeafValues::String(Kind::kBytes, std::string(TakeBytes(TakeLittleEndian(8)))));
      return true;
    case 'V': {  // UNICODE
      const std::string_view line = TakeLine();
      std::string text;
      if (!RawUnicodeEscapeToUtf8(line, text)) {
        Fail(Here() + ": " + Quoted(line) + " has an escape that is not read");
      }
      Push(LeafValues::String(Kind::kText, std::move(text)));
      return true;
    }
    case 0x8c:  // SHORT_BINUNICODE
      Push(LeafValues::String(Kind::kText, std::string(TakeBytes(TakeLittleEndian(1)))));
      return true;
    case 'X':  // BINUNICODE
      Push(LeafValues::String(Kind::kText, std::string(TakeBytes(TakeLittleEndian(4)))));
      return true;
    case 0x8d:  // BINUNICODE8
      Push(LeafValues::String(Kind::kText, std::string(TakeBytes(TakeLittleEndian(8)))));
      return true;
    default:
      return false;
  }
}

// Lists and tuples.
bool PickleMachine::SequenceStep() {
  switch (op_) {
    case ']':  // EMPTY_LIST
      Push(NewContainer(Kind::kList));
      return true;
    case 'l':  // LIST
      Push(NewContainer(Kind::kList, PopMark()));
      return true;
    case 'a':    // APPEND
    case 'e': {  // APPENDS
      std::vector<Value> items;
      if (op_ == 'a') {
        items.push_back(Pop());
      } else {
        items = PopMark();
      }
      PyValue& list = *Top();
      if (list.kind != Kind::kList) Fail(Here() + " appends to " + Describe(list) + ", not a list");
      list.items.insert(list.items.end(), std::make_move_iterator(items.begin()),
                        std::make_move_iterator(items.end()));
      return true;
    }
    case ')':  // EMPTY_TUPLE
      Push(NewContainer(Kind::kTuple));
      return true;
    case 't':  // TUPLE
      Push(NewContainer(Kind::kTuple, PopMark()));
      return true;
    case 0x85:    // TUPLE1
    case 0x86:    // TUPLE2
    case 0x87: {  // TUPLE3
      std::vector<Value> items(static_cast<std::size_t>(op_ - 0x84));
      for (auto it = items.rbegin(); it != items.rend(); ++it) *it = Pop();
      Push(NewContainer(Kind::kTuple, std::move(items)));
      return true;
    }
    default:
      return false;
  }
}

// Dicts: EMPTY_DICT, DICT, SETITEM, SETITEMS.
bool PickleMachine::DictStep() {
  if (op_ == '}') {  // EMPTY_DICT
    Push(NewContainer(Kind::kDict));
    return true;
  }
  if (op_ != 'd' && op_ != 's' && op_ != 'u') return false;
  std::vector<Value> items;
  if (op_ == 's') {  // SETITEM
    items.resize(2);
    items[1] = Pop();
    items[0] = Pop();
  } else {  // DICT, SETITEMS
    items = PopMark();
  }
  if (items.size() % 2 != 0) Fail(Here() + " finds a key without a value");
  if (op_ == 'd') {
    Push(NewContainer(Kind::kDict, std::move(items)));
    return true;
  }
  PyValue& dict = *Top();
  if (dict.kind != Kind::kDict) Fail(Here() + " sets items of " + Describe(dict));
  dict.items.insert(dict.items.end(), std::make_move_iterator(items.begin()),
                    std::make_move_iterator(items.end()));
  return true;
}

// The memo: GET, BINGET, LONG_BINGET, PUT, BINPUT, LONG_BINPUT, MEMOIZE.
bool PickleMachine::MemoStep() {
  switch (op_) {
    case 'g':    // GET
    case 'h':    // BINGET
    case 'j': {  // LONG_BINGET
      const std::uint64_t key = op_ == 'g'   ? static_cast<std::uint64_t>(LineInteger(TakeLine()))
                                : op_ == 'h' ? TakeLittleEndian(1)
                                             : TakeLittleEndian(4);
      const auto it = memo_.find(key);
      if (it == memo_.end()) Fail(Here() + " reads memo entry " + std::to_string(key) + ", unset");
      Push(it->second);
      return true;
    }
    case 'p':     // PUT
    case 'q':     // BINPUT
    case 'r':     // LONG_BINPUT
    case 0x94: {  // MEMOIZE
      const std::uint64_t key = op_ == 'p'   ? static_cast<std::uint64_t>(LineInteger(TakeLine()))
                                : op_ == 'q' ? TakeLittleEndian(1)
                                : op_ == 'r' ? TakeLittleEndian(4)
                                             : memo_.size();
      memo_[key] = Top();
      return true;
    }
    default:
      return false;
  }
}

// The callables allowed and their calls: GLOBAL, STACK_GLOBAL, REDUCE, BUILD.
bool PickleMachine::CallStep() {
  switch (op_) {
    case 'c': {  // GLOBAL
      const std::string_view module = TakeLine();
      Global(module, TakeLine());
      return true;
    }
    case 0x93: {  // STACK_GLOBAL
      const Value name = Pop();
      const Value module = Pop();
      if (module->kind != Kind::kText || name->kind != Kind::kText) {
        Fail(Here() + " takes two strings, not " + Describe(*module) + " and " + Describe(*name));
      }
      Global(module->text, name->text);
      return true;
    }
    case 'R': {  // REDUCE
      const Value args = Pop();
      const Value f = Pop();
      Push(Call(*f, *args));
      return true;
    }
    case 'b': {  // BUILD
      const Value state = Pop();
      Build(Top(), *state);
      return true;
    }
    default:
      return false;
  }
}

// Any other opcode: one that would run code or make other objects, or none at all.
void PickleMachine::RefuseOpcode() const {
  const std::string name = PickleOpName(op_);
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", op_);
  if (name.empty()) {
    Fail("unknown pickle opcode " + std::string(hex) + " at byte " + std::to_string(op_at_) +
         " (not a pickle of protocol 0-5, or a damaged one)");
  }
  Fail("pickle opcode " + name + " (" + hex + ") at byte " + std::to_string(op_at_) +
       " is refused: only NumPy arrays, lists, tuples, dicts, numbers and strings are read");
}

void PickleMachine::Global(std::string_view module, std::string_view name) {
  const bool multiarray = module == "numpy.core.multiarray" || module == "numpy._core.multiarray";
  const bool numeric = module == "numpy.core.numeric" || module == "numpy._core.numeric";
  const bool builtins = module == "builtins" || module == "__builtin__";
  const bool numpy_type = module == "numpy" || multiarray;
  const std::string full = std::string(module) + "." + std::string(name);
  Callable callable;
  if (multiarray && name == "_reconstruct") {
    callable = Callable::kReconstruct;
  } else if (multiarray && name == "scalar") {
    callable = Callable::kScalar;
  } else if (numpy_type && name == "ndarray") {
    callable = Callable::kNdarray;
  } else if (numpy_type && name == "dtype") {
    callable = Callable::kDtype;
  } else if (numeric && name == "_frombuffer") {
    callable = Callable::kFromBuffer;
  } else if (module == "_codecs" && name == "encode") {
    callable = Callable::kEncode;
  } else if ((module == "builtins" && name == "range") ||
             (module == "__builtin__" && name == "xrange")) {
    callable = Callable::kRange;
  } else if (builtins && name == "bytes") {
    callable = Callable::kBytes;
  } else {
    Fail("refuses to call " + Escaped(full) +
         ": only NumPy arrays, lists, tuples, numbers and strings are read (the file may run "
         "code when loaded with allow_pickle=True)");
  }
  PickleSpecial& s = NewSpecial(full);
  s.callable = callable;
  Push(s.self);
}

Value PickleMachine::Call(const PyValue& f, const PyValue& args) {
  const PickleSpecial* callee = SpecialOf(f);
  if (callee == nullptr || callee->is_dtype) Fail(Here() + " calls " + Describe(f));
  const std::string& name = callee->name;
  if (args.kind != Kind::kTuple) {
    Fail(Here() + ": the arguments of " + name + " are " + Describe(args) + ", not a tuple");
  }
  const std::vector<Value>& a = args.items;
  const auto expect = [&](std::size_t low, std::size_t high) {
    if (a.size() < low || a.size() > high) {
      Fail(Here() + " calls " + name + " with " + std::to_string(a.size()) + " arguments");
    }
  };
  switch (callee->callable) {
    case Callable::kReconstruct: {
      expect(3, 3);
      const PickleSpecial* cls = SpecialOf(*a[0]);
      if (cls == nullptr || cls->is_dtype || cls->callable != Callable::kNdarray) {
        Fail(Here() + ": " + name + " makes numpy.ndarray only, not " + Describe(*a[0]));
      }
      const Value array = NewContainer(Kind::kArray);
      pending_.insert(array.get());
      return array;
    }
    case Callable::kNdarray:
      Fail(Here() + " calls numpy.ndarray; arrays are read from _reconstruct and BUILD only");
    case Callable::kDtype: {
      expect(1, 3);
      const std::string type = TextOf(*a[0], "the dtype's name");
      NumpyDtype d;
      if (!DtypeFromName(type, '=', d)) {
        Fail("dtype " + Quoted(type) + " is not read; " + kDtypesRead);
      }
      PickleSpecial& s = NewSpecial("numpy.dtype");
      s.is_dtype = true;
      s.dtype = d;
      return s.self;
    }
    case Callable::kScalar: {
      expect(2, 2);
      const NumpyDtype d = DtypeOf(*a[0], "the scalar's dtype").dtype;
      if (d.kind == 'O') Fail(Here() + ": a NumPy object scalar is not read");
      CheckByteOrder(d, where_);
      if (a[1]->kind != Kind::kBytes || a[1]->text.size() != static_cast<std::size_t>(d.size)) {
        Fail(Here() + ": the scalar's data are not " + std::to_string(d.size) + " bytes");
      }
      return ElementValue(d, reinterpret_cast<const unsigned char*>(a[1]->text.data()), leaves_,
                          where_);
    }
    case Callable::kFromBuffer: {
      expect(4, 4);
      if (a[0]->kind != Kind::kBytes) {
        Fail(Here() + ": the buffer is " + Describe(*a[0]) + ", not bytes");
      }
      const NumpyDtype d = DtypeOf(*a[1], "the buffer's dtype").dtype;
      if (d.kind == 'O') Fail(Here() + ": an object array cannot come from a buffer");
      std::vector<std::int64_t> shape = ShapeOf(*a[2]);
      const std::string order = TextOf(*a[3], "the order");
      if (order != "C" && order != "F") Fail(Here() + ": order " + Quoted(order) + " is not read");
      CountItems(ElementCount(shape, where_), false);
      const Value array = NewContainer(
          Kind::kArray, NumericElements(d, shape, order == "F", a[0]->text, leaves_, where_));
      array->shape = std::move(shape);
      return array;
    }
    case Callable::kEncode: {
      expect(2, 2);
      const std::string text = TextOf(*a[0], "the text to encode");
      std::string encoding = TextOf(*a[1], "the encoding");
      std::transform(encoding.begin(), encoding.end(), encoding.begin(),
                     [](char c) { return c == '_' ? '-' : (c >= 'A' && c <= 'Z' ? c + 32 : c); });
      if (encoding != "latin1" && encoding != "latin-1" && encoding != "iso-8859-1") {
        Fail(Here() + ": _codecs.encode to " + Quoted(encoding) + " is not read (latin1 is)");
      }
      std::string bytes;
      if (a[0]->kind != Kind::kText || !Latin1FromUtf8(text, bytes)) {
        Fail(Here() + ": the text to encode is not latin-1");
      }
      return LeafValues::String(Kind::kBytes, std::move(bytes));
    }
    case Callable::kRange:
      expect(1, 3);
      return Range(a);
    case Callable::kBytes:
      expect(0, 0);
      return LeafValues::String(Kind::kBytes, "");
  }
  Fail(Here() + " calls " + name);
}

// A range, as the list of its numbers.
Value PickleMachine::Range(const std::vector<Value>& args) {
  std::int64_t start = 0, stop = 0, step = 1;
  if (args.size() == 1) {
    stop = IntegerOf(*args[0], "the range's end");
  } else {
    start = IntegerOf(*args[0], "the range's start");
    stop = IntegerOf(*args[1], "the range's end");
    if (args.size() == 3) step = IntegerOf(*args[2], "the range's step");
  }
  if (step == 0) Fail(Here() + ": a range with step 0");
  // The count, in unsigned arithmetic: the distance between two int64 fits 64 bits.
  std::uint64_t count = 0;
  if (step > 0 && start < stop) {
    count = (static_cast<std::uint64_t>(stop) - static_cast<std::uint64_t>(start) - 1) /
                static_cast<std::uint64_t>(step) +
            1;
  } else if (step < 0 && start > stop) {
    count = (static_cast<std::uint64_t>(start) - static_cast<std::uint64_t>(stop) - 1) /
                (~static_cast<std::uint64_t>(step) + 1) +
            1;
  }
  CountItems(count, true);
  if (count > static_cast<std::uint64_t>(std::max<std::int64_t>(0, limits_.range))) {
    Fail(Here() + ": range(" + std::to_string(start) + ", " + std::to_string(stop) + ", " +
         std::to_string(step) + ") makes " + std::to_string(count) + " numbers; expected at most " +
         std::to_string(limits_.range) + " in one list" + Why());
  }
  std::vector<Value> items;
  items.reserve(count);
  // Unsigned: the step past the last number may leave the int64 range.
  std::uint64_t v = static_cast<std::uint64_t>(start);
  for (std::uint64_t k = 0; k < count; ++k, v += static_cast<std::uint64_t>(step)) {
    items.push_back(leaves_.Int(static_cast<std::int64_t>(v)));
  }
  return NewContainer(Kind::kList, std::move(items));
}

void PickleMachine::Build(const Value& object, const PyValue& state) {
  if (object->kind == Kind::kArray && pending_.count(object.get()) != 0) {
    BuildArray(*object, state);
    return;
  }
  PickleSpecial* s = SpecialOf(*object);
  if (s == nullptr || !s->is_dtype) {
    Fail(Here() + " sets the state of " + Describe(*object) +
         "; only NumPy arrays and dtypes take one");
  }
  // The state of a dtype: (version, byte order, subarray, names, fields, ...).
  if (state.kind != Kind::kTuple || state.items.size() < 2) {
    Fail(Here() + ": the dtype's state is not a tuple of 2 or more items");
  }
  const std::string order = TextOf(*state.items[1], "the dtype's byte order");
  if (order.size() != 1 || std::string_view("<>|=").find(order[0]) == std::string_view::npos) {
    Fail(Here() + ": byte order " + Quoted(order) + " is not '<', '>', '|' or '='");
  }
  for (std::size_t k = 2; k < std::min<std::size_t>(state.items.size(), 5); ++k) {
    if (state.items[k]->kind != Kind::kNone) {
      Fail(Here() + ": structured and sub-array dtypes are not read");
    }
  }
  s->dtype.order = order[0];
}

// The state of an array: ([version,] shape, dtype, is_fortran, data); data are a list of the
// elements, always in C order, for an object array, else bytes in the array's order.
void PickleMachine::BuildArray(PyValue& array, const PyValue& state) {
  if (state.kind != Kind::kTuple || (state.items.size() != 4 && state.items.size() != 5)) {
    Fail(Here() + ": the array's state is not a tuple of 4 or 5 items");
  }
  const std::size_t k = state.items.size() - 4;
  std::vector<std::int64_t> shape = ShapeOf(*state.items[k]);
  const NumpyDtype d = DtypeOf(*state.items[k + 1], "the array's dtype").dtype;
  const bool fortran = IntegerOf(*state.items[k + 2], "the array's order") != 0;
  const PyValue& data = *state.items[k + 3];
  const std::uint64_t count = ElementCount(shape, where_);
  if (d.kind == 'O') {
    if (data.kind != Kind::kList || data.items.size() != count) {
      Fail(Here() + ": the object array of shape " + NpyShapeText(shape) + " holds " +
           Describe(data) +
           (data.kind == Kind::kList ? " of " + std::to_string(data.items.size()) + " items" : "") +
           ", not a list of " + std::to_string(count));
    }
    CountItems(count, false);
    array.items = data.items;
  } else {
    if (data.kind != Kind::kBytes) {
      Fail(Here() + ": the array's data are " + Describe(data) + ", not bytes");
    }
    CountItems(count, false);
    array.items = NumericElements(d, shape, fortran, data.text, leaves_, where_);
  }
  array.shape = std::move(shape);
  pending_.erase(&array);
}

// Checks that `v` holds data only (no callable, dtype or unfinished array), nested at most
// kNpyMaxDepth deep, without a list that holds itself; returns the number of values it unfolds
// into, a list held twice counted twice.
std::uint64_t PickleMachine::Check(const PyValue& v, int depth) {
  if (const PickleSpecial* s = SpecialOf(v)) {
    Fail("the array holds " + (s->is_dtype ? std::string("a numpy.dtype") : s->name) +
         ", which is not data");
  }
  if (v.kind != Kind::kList && v.kind != Kind::kTuple && v.kind != Kind::kDict &&
      v.kind != Kind::kArray) {
    return 1;
  }
  if (v.kind == Kind::kArray && pending_.count(&v) != 0) {
    Fail("the array holds an array whose contents never come (no BUILD)");
  }
  if (depth >= kNpyMaxDepth) {
    Fail("the array's values are nested more than " + std::to_string(kNpyMaxDepth) +
         " levels deep");
  }
  const auto [it, inserted] = unfolded_.emplace(&v, 0);
  if (!inserted) {
    if (it->second == 0) Fail("the array holds " + KindName(v.kind) + " that holds itself");
    return it->second;
  }
  std::uint64_t total = 1;
  for (const Value& item : v.items) {
    total += Check(*item, depth + 1);
    const auto limit = static_cast<std::uint64_t>(
        std::max<std::int64_t>(0, std::min(kNpyMaxUnfoldedValues, limits_.values)));
    if (total > limit) {
      Fail("the array unfolds into " + std::to_string(total) +
           " values or more (lists referred to from several places count at each); expected at "
           "most " +
           std::to_string(limit) + Why());
    }
  }
  unfolded_[&v] = total;
  return total;
}

// ---------------------------------------------------------------------------------------------
// ZIP archives
//
// Read here rather than through a library: a .npz must mean to this reader what it means to
// NumPy, which reads it with Python's zipfile (where the end record is found, the zip64 end
// record just before its locator, bytes before the archive, the local header of the member read
// only). Over Debian 12's libzip 1.7.3 the end-record search stayed hand-written and the
// archive had to be re-presented to it, and its consistency check (ZIP_CHECKCONS, every local
// header) refused 3,397 of 14,000 damaged archives that NumPy reads; the code grew. What is left
// here is small (one central directory, members stored or deflated, zip64 fields); libdeflate
// inflates into a buffer of the size checked beforehand. The layout is PKWARE's APPNOTE.TXT;
// "zipfile" below is CPython's Lib/zipfile.py.

constexpr std::uint32_t kZipLocalHeader = 0x04034b50, kZipCentralHeader = 0x02014b50,
                        kZipEnd = 0x06054b50, kZip64End = 0x06064b50, kZip64EndLocator = 0x07064b50;
constexpr std::uint64_t kZipEndSize = 22, kZipMaxComment = 65535, kZip64EndSize = 56,
                        kZip64LocatorSize = 20;

struct ZipMember {
  std::string name;
  std::uint16_t flags = 0, method = 0;
  std::uint32_t crc = 0;
  std::uint64_t compressed = 0, uncompressed = 0, local_offset = 0;
};

// A little-endian field of `n` bytes at `at`; throws when it lies beyond the archive.
std::uint64_t ZipField(std::string_view zip, std::uint64_t at, int n, const std::string& where) {
  if (at > zip.size() || static_cast<std::uint64_t>(n) > zip.size() - at) {
    throw InputError(where + ": truncated ZIP archive: a field at byte " + std::to_string(at) +
                     " lies beyond its " + std::to_string(zip.size()) + " bytes");
  }
  return LittleEndianAt(reinterpret_cast<const unsigned char*>(zip.data()) + at, n);
}

// The name np.load gives a member: without ".npy" (NpzFile.files).
std::string_view NumpyKey(std::string_view name) {
  constexpr std::string_view kNpy = ".npy";
  if (name.size() >= kNpy.size() && name.substr(name.size() - kNpy.size()) == kNpy) {
    name.remove_suffix(kNpy.size());
  }
  return name;
}

std::vector<ZipMember> ZipMembers(std::string_view zip, const std::string& where) {
  const auto field = [&](std::uint64_t at, int n) { return ZipField(zip, at, n, where); };
  // The end-of-central-directory record: 22 bytes and a comment of up to 65535 at the end.
  // As zipfile finds it: at 22 bytes from the end with no comment, else the last signature
  // among the last 65535 + 22 bytes.
  std::uint64_t end = 0;
  bool found = false;
  if (zip.size() >= kZipEndSize) {
    const std::uint64_t last = zip.size() - kZipEndSize;
    if (field(last, 4) == kZipEnd && field(last + 20, 2) == 0) {
      end = last;
      found = true;
    } else {
      const std::uint64_t lowest = last > kZipMaxComment ? last - kZipMaxComment : 0;
      const std::string_view signature("PK\x05\x06", 4);
      const std::size_t at = zip.rfind(signature);
      found = at != std::string_view::npos && at >= lowest && at <= last;
      end = found ? at : 0;
    }
  }
  if (!found) {
    const bool npy = zip.substr(0, 6) == std::string_view("\x93NUMPY", 6);
    throw InputError(where + ": not a ZIP archive (.npz): no end-of-central-directory record" +
                     (npy ? " (it is a .npy file)" : ""));
  }
  std::uint64_t disk = field(end + 4, 2), directory_disk = field(end + 6, 2);
  std::uint64_t entries = field(end + 10, 2), directory_size = field(end + 12, 4),
                directory_offset = field(end + 16, 4);
  // Zip64: a locator just before the record points to the zip64 end record, whose fields
  // replace those that do not fit 16 or 32 bits (then 0xFFFF or 0xFFFFFFFF). zipfile reads the
  // zip64 record just before the locator, whatever the locator says: both must agree.
  std::uint64_t directory_end_expected = end;
  if (end >= kZip64LocatorSize && field(end - kZip64LocatorSize, 4) == kZip64EndLocator) {
    const std::uint64_t record = field(end - kZip64LocatorSize + 8, 8);
    if (end < kZip64LocatorSize + kZip64EndSize ||
        record != end - kZip64LocatorSize - kZip64EndSize || field(record, 4) != kZip64End) {
      throw InputError(where + ": damaged ZIP archive: no zip64 end record at byte " +
                       std::to_string(record) + " just before its locator");
    }
    disk = field(record + 16, 4);
    directory_disk = field(record + 20, 4);
    entries = field(record + 32, 8);
    directory_size = field(record + 40, 8);
    directory_offset = field(record + 48, 8);
    directory_end_expected = record;
  } else if (entries == 0xffff || directory_size == 0xffffffff || directory_offset == 0xffffffff) {
    throw InputError(where + ": damaged ZIP archive: its zip64 end record is missing");
  }
  if (disk != 0 || directory_disk != 0) {
    throw InputError(where + ": the ZIP archive spans several disks, which is not read");
  }
  if (directory_offset > zip.size() || directory_size > zip.size() - directory_offset) {
    throw InputError(where + ": damaged ZIP archive: its central directory (" +
                     std::to_string(directory_size) + " bytes at byte " +
                     std::to_string(directory_offset) + ") lies beyond the file");
  }
  const std::uint64_t directory_end = directory_offset + directory_size;
  // zipfile takes the bytes between the directory's announced end and the end record as other
  // data the archive was appended to, and shifts every offset by as many bytes.
  if (directory_end != directory_end_expected) {
    throw InputError(where + ": damaged ZIP archive: its central directory ends at byte " +
                     std::to_string(directory_end) + ", its end record is at byte " +
                     std::to_string(directory_end_expected) +
                     "; expected them to meet (NumPy would read the members at offsets moved by " +
                     "the difference)");
  }
  std::vector<ZipMember> members;
  std::uint64_t p = directory_offset;
  for (std::uint64_t i = 0; i < entries; ++i) {
    if (directory_end - p < 46 || field(p, 4) != kZipCentralHeader) {
      throw InputError(where + ": damaged ZIP archive: its central directory holds " +
                       std::to_string(i) + " members of the " + std::to_string(entries) +
                       " announced");
    }
    ZipMember m;
    m.flags = static_cast<std::uint16_t>(field(p + 8, 2));
    m.method = static_cast<std::uint16_t>(field(p + 10, 2));
    m.crc = static_cast<std::uint32_t>(field(p + 16, 4));
    m.compressed = field(p + 20, 4);
    m.uncompressed = field(p + 24, 4);
    const std::uint64_t name_size = field(p + 28, 2), extra_size = field(p + 30, 2),
                        comment_size = field(p + 32, 2);
    m.local_offset = field(p + 42, 4);
    if (directory_end - p - 46 < name_size + extra_size + comment_size) {
      throw InputError(where + ": damaged ZIP archive: a central directory entry at byte " +
                       std::to_string(p) + " runs past the directory");
    }
    m.name = std::string(zip.substr(p + 46, name_size));
    // Extra fields: (id, size, data)...; the zip64 one (id 1) holds, in this order, the
    // uncompressed size, compressed size and local header offset whose fields hold 0xFFFFFFFF.
    const std::uint64_t extra = p + 46 + name_size, extra_end = extra + extra_size;
    for (std::uint64_t q = extra; extra_end - q >= 4;) {
      const std::uint64_t id = field(q, 2), size = field(q + 2, 2);
      if (size > extra_end - q - 4) break;
      if (id == 1) {
        std::uint64_t r = q + 4;
        for (std::uint64_t* value : {&m.uncompressed, &m.compressed, &m.local_offset}) {
          if (*value != 0xffffffff) continue;
          if (q + 4 + size - r < 8) {
            throw InputError(where + ": damaged ZIP archive: the zip64 field of " + Quoted(m.name) +
                             " is too short");
          }
          *value = field(r, 8);
          r += 8;
        }
      }
      q += 4 + size;
    }
    members.push_back(std::move(m));
    p += 46 + name_size + extra_size + comment_size;
  }
  // zipfile reads entries to the directory's end, whatever count the end record announces.
  if (p != directory_end) {
    throw InputError(where + ": damaged ZIP archive: its central directory holds " +
                     std::to_string(directory_end - p) + " bytes after the " +
                     std::to_string(entries) +
                     " members its end record announces (NumPy would read them as more members)");
  }
  // Two members of one name: zipfile (so np.load) reads the last, this reader would read the
  // first. Names np.load takes for one ("GThard" and "GThard.npy") are refused as well.
  std::unordered_map<std::string_view, std::size_t> first_of;
  for (std::size_t k = 0; k < members.size(); ++k) {
    const auto [it, inserted] = first_of.emplace(NumpyKey(members[k].name), k);
    if (inserted) continue;
    const ZipMember& first = members[it->second];
    const std::string names = first.name == members[k].name
                                  ? "two members named " + Quoted(first.name)
                                  : "members named " + Quoted(first.name) + " and " +
                                        Quoted(members[k].name) + ", which np.load takes for one";
    throw InputError(where + ": the archive holds " + names + " (entries " +
                     std::to_string(it->second + 1) + " and " + std::to_string(k + 1) +
                     " of its central directory); expected one member of each name (NumPy reads "
                     "the last of them, this reader would read the first: save the arrays "
                     "again with np.savez or np.savez_compressed)");
  }
  return members;
}

std::string CompressionName(int method) {
  switch (method) {
    case 9:
      return "deflate64";
    case 12:
      return "bzip2";
    case 14:
      return "LZMA";
    case 93:
      return "Zstandard";
    case 95:
      return "xz";
    default:
      return "method " + std::to_string(method);
  }
}

struct InflaterDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

}  // namespace

NpyObjects DecodeNpyObjects(std::string_view data, const std::string& where,
                            const NpyObjectLimits& limits) {
  const NpyHeaderInfo header = ReadNpyHeader(data, where);
  std::string_view name = header.descr;
  char order = '=';
  if (!name.empty() && std::string_view("<>|=").find(name[0]) != std::string_view::npos) {
    order = name[0];
    name.remove_prefix(1);
  }
  NumpyDtype dtype;
  if (!DtypeFromName(name, order, dtype)) {
    throw InputError(where + ": dtype " + Quoted(header.descr) + " is not read; " + kDtypesRead);
  }
  // The elements the header announces, before any is read.
  const std::uint64_t count = ElementCount(header.shape, where);
  const auto most = static_cast<std::uint64_t>(
      std::max<std::int64_t>(0, std::min(kNpyMaxObjectItems, limits.values)));
  if (count > most) {
    throw InputError(where + ": shape " + NpyShapeText(header.shape) + " holds " +
                     std::to_string(count) + " elements; expected at most " + std::to_string(most) +
                     (limits.expected.empty() ? std::string() : " (" + limits.expected + ")"));
  }
  NpyObjects out;
  if (dtype.kind == 'O') {
    PickleMachine machine(data.substr(header.data_offset), where, limits);
    const Value array = machine.Run();
    if (array->shape != header.shape) {
      throw InputError(where + ": the pickled array has shape " + NpyShapeText(array->shape) +
                       ", the header says " + NpyShapeText(header.shape));
    }
    out.shape = array->shape;
    out.items.assign(array->items.begin(), array->items.end());
    return out;
  }
  CheckByteOrder(dtype, where);
  const std::uint64_t available = data.size() - header.data_offset;
  const auto size = static_cast<std::uint64_t>(dtype.size);
  if (count > available / size) {
    throw InputError(where + ": truncated data: " + std::to_string(available) +
                     " bytes, expected " + std::to_string(count) + " x " + std::to_string(size) +
                     " for shape " + NpyShapeText(header.shape) + " of " + header.descr);
  }
  const LeafValues leaves;
  std::vector<Value> items =
      NumericElements(dtype, header.shape, header.fortran_order,
                      data.substr(header.data_offset, count * size), leaves, where);
  out.shape = header.shape;
  out.items.assign(std::make_move_iterator(items.begin()), std::make_move_iterator(items.end()));
  return out;
}

std::vector<std::string> NpzMemberNames(std::string_view zip, const std::string& where) {
  std::vector<std::string> names;
  for (ZipMember& m : ZipMembers(zip, where)) names.push_back(std::move(m.name));
  return names;
}

bool IsNpzArchive(std::string_view bytes) {
  const std::string_view head = bytes.substr(0, 4);
  return head == std::string_view("PK\x03\x04", 4) || head == std::string_view("PK\x05\x06", 4);
}

std::string NpzMember(std::string_view zip, const std::string& name, const std::string& where,
                      const NpzLimit& limit) {
  const std::vector<ZipMember> members = ZipMembers(zip, where);
  if (members.empty()) {
    throw InputError(where + ": is an empty ZIP archive (no member); expected one holding " +
                     Quoted(name));
  }
  const auto named = [&](const std::string& n) {
    return std::find_if(members.begin(), members.end(),
                        [&](const ZipMember& m) { return m.name == n; });
  };
  auto it = named(name);
  if (it == members.end()) it = named(name + ".npy");
  if (it == members.end()) {
    std::string list;
    constexpr std::size_t kListed = 20;
    for (std::size_t k = 0; k < members.size() && k < kListed; ++k) {
      list += (k ? ", " : "") + Quoted(members[k].name);
    }
    if (members.size() > kListed) {
      list += " and " + std::to_string(members.size() - kListed) + " more";
    }
    throw InputError(where + ": has no member " + Quoted(name) + "; its members are " + list);
  }
  const ZipMember& m = *it;
  const std::string member = where + ": member " + Quoted(m.name);
  if ((m.flags & 1) != 0) throw InputError(member + " is encrypted, which is not read");
  if (m.method != 0 && m.method != 8) {
    throw InputError(member + " is compressed with " + CompressionName(m.method) +
                     ", which is not read; expected stored or deflate (np.savez, "
                     "np.savez_compressed)");
  }
  // The declared size bounds what is allocated: the data are inflated into a buffer of that
  // size, and data that would inflate to more are refused as damaged.
  if (m.uncompressed > limit.bytes) {
    throw InputError(member + " holds " + std::to_string(m.uncompressed) +
                     " bytes once inflated (the size the archive declares); expected at most " +
                     std::to_string(limit.bytes) +
                     (limit.expected.empty() ? std::string() : ": " + limit.expected));
  }
  // The local header repeats the name and has extra fields of its own, before the data.
  if (ZipField(zip, m.local_offset, 4, where) != kZipLocalHeader) {
    throw InputError(member + ": no local header at byte " + std::to_string(m.local_offset));
  }
  const std::uint64_t local_name_size = ZipField(zip, m.local_offset + 26, 2, where);
  const std::uint64_t start =
      m.local_offset + 30 + local_name_size + ZipField(zip, m.local_offset + 28, 2, where);
  // zipfile refuses a member whose local header names another file.
  if (m.local_offset + 30 > zip.size() || local_name_size > zip.size() - m.local_offset - 30 ||
      zip.substr(m.local_offset + 30, local_name_size) != m.name) {
    throw InputError(member + ": its local header at byte " + std::to_string(m.local_offset) +
                     " names another file; expected the name of the central directory");
  }
  if (start > zip.size() || m.compressed > zip.size() - start) {
    throw InputError(member + ": truncated ZIP archive: " + std::to_string(m.compressed) +
                     " bytes at byte " + std::to_string(start) + " run past the end of the file");
  }
  const std::string_view stored = zip.substr(start, m.compressed);
  std::string out;
  if (m.method == 0) {
    if (m.uncompressed != m.compressed) {
      throw InputError(member + " is stored with sizes that differ (" +
                       std::to_string(m.compressed) + " and " + std::to_string(m.uncompressed) +
                       " bytes)");
    }
    out.assign(stored);
  } else {
    // Deflate shrinks data 1032 times at most: a larger size is a damaged or hostile archive.
    if (m.uncompressed / 1032 > m.compressed + 1) {
      throw InputError(member + " announces " + std::to_string(m.uncompressed) + " bytes from " +
                       std::to_string(m.compressed) + " compressed, more than deflate makes");
    }
    const std::unique_ptr<libdeflate_decompressor, InflaterDeleter> inflater(
        libdeflate_alloc_decompressor());
    if (!inflater) throw std::bad_alloc();
    out.resize(m.uncompressed);
    std::size_t made = 0;
    const libdeflate_result r = libdeflate_deflate_decompress(
        inflater.get(), stored.data(), stored.size(), out.data(), out.size(), &made);
    if (r != LIBDEFLATE_SUCCESS || made != out.size()) {
      throw InputError(member + ": damaged deflate data (they do not inflate to the " +
                       std::to_string(m.uncompressed) + " bytes announced)");
    }
  }
  const std::uint32_t crc = libdeflate_crc32(0, out.data(), out.size());
  if (crc != m.crc) {
    char text[64];
    std::snprintf(text, sizeof text, "CRC-32 0x%08x, the archive says 0x%08x", crc, m.crc);
    throw InputError(member + " is damaged: its data have " + text);
  }
  return out;
}

}  // namespace openable
