// NumPy files that hold Python objects, and .npz archives. An object array (dtype '|O') is a
// pickle, as in VPR-Bench's ground_truth_new.npy ((Q, 2): query index, list of true references).
// Unpickling runs whatever callables a file names, so DecodeNpyObjects does not unpickle: a small
// interpreter reads the opcodes plain data use and calls only the few NumPy and builtin
// constructors of arrays, dtypes, numbers, bytes and ranges; anything else is refused. A .npz
// (np.savez) is a ZIP of .npy members, as VPR_Tutorial's GT.npz (GThard.npy, GTsoft.npy).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace openable {

// A value read from a pickled NumPy object array. Values may be shared (a list the pickle
// refers to twice, small numbers): treat them as read-only.
struct PyValue {
  enum class Kind { kNone, kBool, kInt, kFloat, kText, kBytes, kList, kTuple, kDict, kArray };
  Kind kind = Kind::kNone;
  std::int64_t integer = 0;  // kBool (0 or 1), kInt
  double real = 0;           // kFloat
  std::string text;          // kText (UTF-8), kBytes (Python 2 strings are bytes)
  // kList (also a materialised range), kTuple; kArray: the elements in C order;
  // kDict: key, value, key, value, ...
  std::vector<std::shared_ptr<PyValue>> items;
  std::vector<std::int64_t> shape;  // kArray
};

// The elements of a .npy file's array, in C order, with its shape: an object array ('|O',
// pickled) or a numeric one (then each element is a kBool/kInt/kFloat value).
struct NpyObjects {
  std::vector<std::int64_t> shape;
  std::vector<std::shared_ptr<const PyValue>> items;
};

// Limits that keep a small hostile file from taking much memory or time, whatever the caller
// expects (NpyObjectLimits lowers them). The numbers the range objects of one file make in all
// (each a value of some 130 bytes: 130 MB at most), and the elements its arrays hold in all
// (object arrays: a pointer each; numeric arrays read from a pickle: a value each unless it is
// a bool or an integer in [-1, 255]):
constexpr std::int64_t kNpyMaxRangeNumbers = 1'000'000;
constexpr std::int64_t kNpyMaxObjectItems = 10'000'000;
// The values an object array may unfold into, a list it refers to from several places counted
// at each place (what a program walking it visits, once a visit):
constexpr std::int64_t kNpyMaxUnfoldedValues = 20'000'000;
// The deepest nesting of lists, tuples, dicts and arrays read.
constexpr int kNpyMaxDepth = 100;

// What the caller can use of an array, below the limits above: DecodeNpyObjects refuses a file
// whose header announces more elements, whose ranges make more numbers, whose arrays hold more
// elements or whose array unfolds into more values than `values`, or one of whose ranges makes
// more numbers than `range`, each as soon as it is known (the header's before the pickle runs,
// a range's before its numbers are made).
struct NpyObjectLimits {
  std::int64_t values = kNpyMaxUnfoldedValues;
  std::int64_t range = kNpyMaxRangeNumbers;  // the numbers of one range (one list of the file)
  // Why, for messages ("10 queries listing at most 74 reference indices each"); may be empty.
  std::string expected;
};

// Reads the array of a .npy file (versions 1.0-3.0). Pickles of protocols 0-5 are read as
// Python 2 and 3 and NumPy 1 and 2 write them; the callables allowed are
// numpy(.core|._core).multiarray._reconstruct and .scalar, numpy.dtype, numpy.ndarray (as an
// argument), numpy(.core|._core).numeric._frombuffer (protocol 5 arrays), _codecs.encode to
// latin-1, builtins.bytes, and builtins.range / __builtin__.xrange (materialised as lists).
// Numeric dtypes: b1, i1/u1, i2/u2, i4/u4, i8/u8 (u8 values must fit int64), f4, f8,
// little-endian or '|'; C or Fortran order. Throws InputError with one line beginning with
// `where` (the file name as given, e.g. "\"gt.npy\"") on anything it cannot read: not .npy, a
// bad header, a refused callable ("refuses to call posix.system: ..."), truncation ("truncated
// pickle at byte N", counted from the pickle's first byte), a refused or unknown opcode, limits
// above exceeded.
NpyObjects DecodeNpyObjects(std::string_view data, const std::string& where,
                            const NpyObjectLimits& limits = {});

// Whether `bytes` are to be read as a .npz (ZIP) archive, as np.load tells one: they begin with
// a member's local header ("PK\x03\x04") or, for an archive without members, the end record
// ("PK\x05\x06").
bool IsNpzArchive(std::string_view bytes);

// The largest member NpzMember inflates when its caller states no size (1 GiB).
constexpr std::uint64_t kNpzMaxMemberBytes = std::uint64_t{1} << 30;

// The most bytes a member may hold once inflated, and why (for messages: "a 600 x 600 matrix,
// 8 bytes a cell at most, and its header"). NpzMember compares the size the archive declares
// with it before allocating anything, and inflates into a buffer of the declared size only
// (a member that would inflate to more is damaged).
struct NpzLimit {
  std::uint64_t bytes = kNpzMaxMemberBytes;
  std::string expected;
};

// The member names of a .npz (ZIP) archive, in archive order. The archive must mean the same
// to NumPy (np.load, Python's zipfile) as to this reader: two members of one name, or of names
// that np.load takes for one ("GThard" and "GThard.npy"), a central directory that holds other
// entries than its end record announces or does not end where that record says, are refused
// (NumPy would read the last of two members of one name, this reader the first).
std::vector<std::string> NpzMemberNames(std::string_view zip, const std::string& where);
// The bytes of the member `name` ("GThard.npy"; "GThard", as np.load names it, finds
// "GThard.npy" too), stored or deflated, checked against its CRC-32. Throws InputError with
// one line beginning with `where` on a file that is not a ZIP archive, an archive refused by
// NpzMemberNames, an empty archive, a missing member (the message lists the members there
// are), a member larger than `limit` (naming both sizes), a compression method other than
// stored and deflate, encryption, a local header whose name is not the member's, a CRC-32
// mismatch, sizes or offsets beyond the file.
std::string NpzMember(std::string_view zip, const std::string& name, const std::string& where,
                      const NpzLimit& limit = {});

}  // namespace openable
