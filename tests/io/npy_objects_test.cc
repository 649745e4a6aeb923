// Pickled NumPy object arrays and .npz archives: the files of tests/data/npy_objects (written by
// its make.py, whose values are stated here), hand-written pickles, and damaged or hostile bytes.
#include "OpenABLE/io/npy_objects.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/npy.h"
#include "tests/io/zip_writer.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace std::string_literals;
using testing::ExpectInputError;
using testing::InputErrorMessage;
using testing::Q;
using testing::ReadBytes;
using testing::ZipArchive;
using testing::ZipEntry;
using Kind = PyValue::Kind;

std::string DataPath(const std::string& name) {
  return testing::SourceDir() + "/tests/data/npy_objects/" + name;
}

std::string Data(const std::string& name) {
  const std::string bytes = ReadBytes(DataPath(name));
  EXPECT_FALSE(bytes.empty()) << DataPath(name);
  return bytes;
}

// The integers of a list, tuple or array of ints (an empty vector and a failure otherwise).
std::vector<std::int64_t> Ints(const PyValue& v) {
  std::vector<std::int64_t> out;
  EXPECT_TRUE(v.kind == Kind::kList || v.kind == Kind::kTuple || v.kind == Kind::kArray);
  for (const auto& item : v.items) {
    EXPECT_EQ(item->kind, Kind::kInt);
    out.push_back(item->integer);
  }
  return out;
}

using Ints64 = std::vector<std::int64_t>;

// The opcodes of a 1-D object array of `n` elements as Python 2 pickled them with protocol 2
// (VPR-Bench's files): _reconstruct(ndarray, (0,), 'b'), then BUILD with (1, (n,), dtype('O8')
// built with (3, '|', None, None, None, -1, -1, 63), False, <list>), the list pushed by
// `list_ops`.
std::string ObjectArrayOps(std::int32_t n, const std::string& list_ops) {
  std::string n_bytes(4, '\0');  // little-endian
  for (int k = 0; k < 4; ++k) n_bytes[k] = static_cast<char>(n >> (8 * k));
  return "cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\nK\x00\x85U\x01"
         "b\x87R(K\x01J"s +
         n_bytes +
         "\x85"
         "cnumpy\ndtype\nU\x02O8K\x00K\x01\x87R(K\x03U\x01|NNNJ\xff\xff\xff\xffJ\xff\xff\xff\xffK?"
         "tb"
         "\x89"s +
         list_ops + "tb";
}

// A .npy file of that array; `header_shape` replaces the header's shape when given.
std::string ObjectNpy(const std::string& list_ops, int n, const std::string& header_shape = "") {
  const std::string shape = header_shape.empty() ? "(" + std::to_string(n) + ",)" : header_shape;
  return NpyHeaderOf("'|O'", shape) + "\x80\x02"s + ObjectArrayOps(n, list_ops) + ".";
}

// A .npy header for an object array of shape (1,) followed by `pickle`.
std::string WithObjectHeader(const std::string& pickle) {
  return NpyHeaderOf("'|O'", "(1,)") + pickle;
}

// make.py: gt[q] = [q, refs[q]] with refs [0, 1], [1, 2, 3], [], [2**40, -5] (np.save).
TEST(NpyObjects, GroundTruthListsSavedByNumpy) {
  const NpyObjects gt = DecodeNpyObjects(Data("gt_lists.npy"), Q("gt_lists.npy"));
  ASSERT_EQ(gt.shape, (Ints64{4, 2}));
  ASSERT_EQ(gt.items.size(), 8u);
  const std::vector<Ints64> refs = {{0, 1}, {1, 2, 3}, {}, {std::int64_t{1} << 40, -5}};
  for (int q = 0; q < 4; ++q) {
    const PyValue& query = *gt.items[2 * q];
    EXPECT_EQ(query.kind, Kind::kInt);
    EXPECT_EQ(query.integer, q);
    EXPECT_EQ(gt.items[2 * q + 1]->kind, Kind::kList);
    EXPECT_EQ(Ints(*gt.items[2 * q + 1]), refs[q]) << "query " << q;
  }
}

// make.py's `mixed` array, element by element, as np.save (protocol 3) and pickle.dumps with
// protocols 0, 2 and 5 write it: each protocol writes ranges, bytes, NumPy arrays and scalars
// through other opcodes and callables.
TEST(NpyObjects, EveryKindOfValueInEachPickleProtocol) {
  for (const std::string name : {"mixed.npy", "mixed_p0.npy", "mixed_p2.npy", "mixed_p5.npy"}) {
    SCOPED_TRACE(name);
    const NpyObjects m = DecodeNpyObjects(Data(name), Q(name));
    ASSERT_EQ(m.shape, Ints64{11});
    ASSERT_EQ(m.items.size(), 11u);
    // 0: np.array([4, 5, 6], dtype=np.int64)
    EXPECT_EQ(m.items[0]->kind, Kind::kArray);
    EXPECT_EQ(m.items[0]->shape, Ints64{3});
    EXPECT_EQ(Ints(*m.items[0]), (Ints64{4, 5, 6}));
    // 1: np.int32(7)
    EXPECT_EQ(m.items[1]->kind, Kind::kInt);
    EXPECT_EQ(m.items[1]->integer, 7);
    // 2: (8, 9)
    EXPECT_EQ(m.items[2]->kind, Kind::kTuple);
    EXPECT_EQ(Ints(*m.items[2]), (Ints64{8, 9}));
    // 3: range(2, 5), a list once read
    EXPECT_EQ(m.items[3]->kind, Kind::kList);
    EXPECT_EQ(Ints(*m.items[3]), (Ints64{2, 3, 4}));
    // 4: [[1, 2], [3]]
    ASSERT_EQ(m.items[4]->kind, Kind::kList);
    ASSERT_EQ(m.items[4]->items.size(), 2u);
    EXPECT_EQ(Ints(*m.items[4]->items[0]), (Ints64{1, 2}));
    EXPECT_EQ(Ints(*m.items[4]->items[1]), Ints64{3});
    // 5: np.asfortranarray(np.arange(6, dtype='<u2').reshape(2, 3)): C order in the result
    EXPECT_EQ(m.items[5]->shape, (Ints64{2, 3}));
    EXPECT_EQ(Ints(*m.items[5]), (Ints64{0, 1, 2, 3, 4, 5}));
    // 6: [np.bool_(True), np.float64(0.5), None, 'text', b'\x00\xff', -2**40, 0.25]
    const PyValue& scalars = *m.items[6];
    ASSERT_EQ(scalars.kind, Kind::kList);
    ASSERT_EQ(scalars.items.size(), 7u);
    EXPECT_EQ(scalars.items[0]->kind, Kind::kBool);
    EXPECT_EQ(scalars.items[0]->integer, 1);
    EXPECT_EQ(scalars.items[1]->kind, Kind::kFloat);
    EXPECT_EQ(scalars.items[1]->real, 0.5);
    EXPECT_EQ(scalars.items[2]->kind, Kind::kNone);
    EXPECT_EQ(scalars.items[3]->kind, Kind::kText);
    EXPECT_EQ(scalars.items[3]->text, "text");
    EXPECT_EQ(scalars.items[4]->kind, Kind::kBytes);
    EXPECT_EQ(scalars.items[4]->text, "\x00\xff"s);
    EXPECT_EQ(scalars.items[5]->kind, Kind::kInt);
    EXPECT_EQ(scalars.items[5]->integer, -(std::int64_t{1} << 40));
    EXPECT_EQ(scalars.items[6]->kind, Kind::kFloat);
    EXPECT_EQ(scalars.items[6]->real, 0.25);
    // 7: {'key': 1}
    const PyValue& dict = *m.items[7];
    ASSERT_EQ(dict.kind, Kind::kDict);
    ASSERT_EQ(dict.items.size(), 2u);
    EXPECT_EQ(dict.items[0]->text, "key");
    EXPECT_EQ(dict.items[1]->integer, 1);
    // 8: np.zeros(0, dtype=np.int64)
    EXPECT_EQ(m.items[8]->kind, Kind::kArray);
    EXPECT_EQ(m.items[8]->shape, Ints64{0});
    EXPECT_TRUE(m.items[8]->items.empty());
    // 9: an object array [None, 1]
    const PyValue& nested = *m.items[9];
    ASSERT_EQ(nested.kind, Kind::kArray);
    EXPECT_EQ(nested.shape, Ints64{2});
    ASSERT_EQ(nested.items.size(), 2u);
    EXPECT_EQ(nested.items[0]->kind, Kind::kNone);
    EXPECT_EQ(nested.items[1]->integer, 1);
    // 10: [shared, shared] with shared = [5]: one list, referred to twice
    const PyValue& twice = *m.items[10];
    ASSERT_EQ(twice.items.size(), 2u);
    EXPECT_EQ(twice.items[0].get(), twice.items[1].get());
    EXPECT_EQ(Ints(*twice.items[0]), Ints64{5});
  }
}

// make.py: int32 [[-2, -1, 0], [1, 2, 3]] in Fortran order; DecodeNpyObjects gives C order.
TEST(NpyObjects, NumericFilesGiveNumbersInCOrder) {
  const NpyObjects m = DecodeNpyObjects(Data("numeric_fortran.npy"), Q("numeric_fortran.npy"));
  EXPECT_EQ(m.shape, (Ints64{2, 3}));
  std::vector<std::int64_t> values;
  for (const auto& v : m.items) {
    EXPECT_EQ(v->kind, Kind::kInt);
    values.push_back(v->integer);
  }
  EXPECT_EQ(values, (Ints64{-2, -1, 0, 1, 2, 3}));

  cv::Mat1f f(1, 2);
  f << 1.5f, -0.25f;
  const NpyObjects floats = DecodeNpyObjects(EncodeNpy(f), "f.npy");
  EXPECT_EQ(floats.shape, (Ints64{1, 2}));
  ASSERT_EQ(floats.items.size(), 2u);
  EXPECT_EQ(floats.items[0]->kind, Kind::kFloat);
  EXPECT_EQ(floats.items[0]->real, 1.5);
  EXPECT_EQ(floats.items[1]->real, -0.25);
}

// VPR-Bench's datasets/Living/ground_truth_new.npy (SOURCE.md), a Python 2 pickle: np.load shows
// row q as [q, [q - 1, q, q + 1]] clipped to 0..31.
TEST(NpyObjects, VprBenchGroundTruth) {
  const NpyObjects gt = DecodeNpyObjects(Data("gt_Living.npy"), Q("gt_Living.npy"));
  ASSERT_EQ(gt.shape, (Ints64{32, 2}));
  for (int q = 0; q < 32; ++q) {
    EXPECT_EQ(gt.items[2 * q]->kind, Kind::kInt);
    EXPECT_EQ(gt.items[2 * q]->integer, q);
    Ints64 refs;
    for (int r = std::max(0, q - 1); r <= std::min(31, q + 1); ++r) refs.push_back(r);
    EXPECT_EQ(Ints(*gt.items[2 * q + 1]), refs) << "query " << q;
  }
}

// A pickle that calls posix.system when Python loads it: refused before anything is called.
TEST(NpyObjects, RefusesCallablesWithoutRunningThem) {
  ExpectInputError(
      [] { DecodeNpyObjects(Data("evil.npy"), Q("evil.npy")); },
      {Q("evil.npy") + ": refuses to call posix.system: only NumPy arrays", "allow_pickle=True"});

  const std::string marker = testing::TempDir() + "/ran";
  const std::string command = "touch " + marker;
  const std::string evil =
      "\x80\x02"
      "cposix\nsystem\nX"s +
      std::string(1, static_cast<char>(command.size())) + "\0\0\0"s + command + "\x85R."s;
  ExpectInputError([&] { DecodeNpyObjects(WithObjectHeader(evil), "e.npy"); },
                   {"e.npy: refuses to call posix.system"});
  EXPECT_FALSE(std::filesystem::exists(marker));

  // GLOBAL and STACK_GLOBAL (protocol 4) of other callables, also inside an array's list.
  ExpectInputError([] { DecodeNpyObjects(WithObjectHeader("cbuiltins\neval\n."), "e.npy"); },
                   {"refuses to call builtins.eval"});
  ExpectInputError(
      [] { DecodeNpyObjects(WithObjectHeader("\x8c\x02os\x8c\x06system\x93."s), "e.npy"); },
      {"refuses to call os.system"});
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(csubprocess\nPopen\nl", 1), "e.npy"); },
                   {"refuses to call subprocess.Popen"});
  ExpectInputError([] { DecodeNpyObjects(WithObjectHeader("ccopy_reg\n_reconstructor\n."), "e"); },
                   {"refuses to call copy_reg._reconstructor"});
  // An allowed name used otherwise than NumPy does.
  ExpectInputError(
      [] {
        DecodeNpyObjects(
            WithObjectHeader("cnumpy.core.multiarray\n_reconstruct\ncnumpy\ndtype\n)U\x01"
                             "b\x87R."s),
            "e");
      },
      {"_reconstruct makes numpy.ndarray only"});
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(cnumpy\ndtype\nl", 1), "e"); },
                   {"e: the array holds numpy.dtype, which is not data"});
}

TEST(NpyObjects, RefusedAndUnknownOpcodesAreNamed) {
  // Byte offsets count from the pickle's first byte.
  const struct {
    std::string pickle;
    std::string expected;
  } cases[] = {
      {"(i__main__\nC\n.", "pickle opcode INST (0x69) at byte 1 is refused"},
      {"\x80\x02N)o.", "pickle opcode OBJ (0x6f) at byte 4 is refused"},
      {"\x80\x02N)\x81.", "pickle opcode NEWOBJ (0x81) at byte 4 is refused"},
      {"\x80\x04N))}\x92.", "NEWOBJ_EX (0x92) at byte 6"},
      {"P1\n.", "pickle opcode PERSID (0x50) at byte 0"},
      {"K\x01Q.", "BINPERSID (0x51) at byte 2"},
      {"\x82\x01.", "EXT1 (0x82) at byte 0"},
      {"\x80\x05\x97.", "NEXT_BUFFER (0x97) at byte 2"},
      {"\x80\x04\x8f.", "EMPTY_SET (0x8f) at byte 2"},
      {"\x80\x02\xff.", "unknown pickle opcode 0xff at byte 2"},
      {"z.", "unknown pickle opcode 0x7a at byte 0"},
      {"\x80\x06N.", "pickle protocol 6 is not read"},
  };
  for (const auto& c : cases) {
    ExpectInputError([&] { DecodeNpyObjects(WithObjectHeader(c.pickle), "x.npy"); },
                     {"x.npy: ", c.expected});
  }
}

// Every prefix of each file is refused with one line naming it, never read past its end.
TEST(NpyObjects, TruncatedFilesAreRefused) {
  for (const std::string name : {"gt_lists.npy", "mixed.npy", "mixed_p0.npy", "mixed_p2.npy",
                                 "mixed_p5.npy", "gt_Living.npy", "numeric_fortran.npy"}) {
    const std::string bytes = Data(name);
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      // A copy of the prefix alone, so that a read past its end is seen by sanitizers.
      const std::string prefix = bytes.substr(0, n);
      const std::string message = InputErrorMessage([&] { DecodeNpyObjects(prefix, Q(name)); });
      ASSERT_EQ(message.rfind(Q(name) + ": ", 0), 0u) << name << " cut at " << n << ": " << message;
      ASSERT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  const std::string bytes = Data("gt_lists.npy");
  const std::size_t pickle = ReadNpyHeader(bytes, "x").data_offset;
  ExpectInputError([&] { DecodeNpyObjects(bytes.substr(0, bytes.size() - 1), "g"); },
                   {"g: truncated pickle at byte " + std::to_string(bytes.size() - 1 - pickle) +
                    " (it ends before its STOP opcode)"});
  // A BINUNICODE announcing more bytes than there are.
  ExpectInputError(
      [] {
        DecodeNpyObjects(WithObjectHeader("X\xff\xff\xff\x7f"
                                          "abc."s),
                         "g");
      },
      {"g: truncated pickle at byte 0 (BINUNICODE runs past the end of the file)"});
}

// Random bytes after a header, and random changes to good files: an InputError or a result,
// never a crash or another exception.
TEST(NpyObjects, GarbageAndDamagedBytesAreRefused) {
  ExpectInputError([] { DecodeNpyObjects("garbage bytes, not a .npy file", "g"); },
                   {"g: not a NumPy .npy file"});
  std::mt19937 random(20240611);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string pickle(static_cast<std::size_t>(trial % 64 + 1), '\0');
    for (char& c : pickle) c = static_cast<char>(byte(random));
    try {
      DecodeNpyObjects(WithObjectHeader(pickle), "g");
    } catch (const InputError&) {
    }
  }
  for (const std::string name : {"mixed.npy", "mixed_p0.npy", "mixed_p5.npy", "gt_Living.npy"}) {
    const std::string good = Data(name);
    const std::size_t start = ReadNpyHeader(good, "x").data_offset;
    std::uniform_int_distribution<std::size_t> where(start, good.size() - 1);
    for (int trial = 0; trial < 1000; ++trial) {
      std::string bytes = good;
      for (int k = 0; k <= trial % 3; ++k) bytes[where(random)] = static_cast<char>(byte(random));
      try {
        DecodeNpyObjects(bytes, "g");
      } catch (const InputError&) {
      }
    }
  }
}

TEST(NpyObjects, HostileStructuresAreRefused) {
  // A list that holds itself.
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(]q\x00h\x00\x61l"s, 1), "h"); },
                   {"h: the array holds a list that holds itself"});
  // Lists nested far deeper than any data: refused, and freed without a deep recursion.
  const auto nested = [](int depth) {
    return std::string(static_cast<std::size_t>(depth), ']') +
           std::string(static_cast<std::size_t>(depth - 1), 'a');
  };
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy("(" + nested(150) + "l", 1), "h"); },
                   {"nested more than 100 levels deep"});
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy("(" + nested(300000) + "l", 1), "h"); },
                   {"nested more than 100 levels deep"});
  // An error part way leaves the same chain on the stack, freed as well.
  ExpectInputError([&] { DecodeNpyObjects(WithObjectHeader(nested(300000) + "z"), "h"); },
                   {"unknown pickle opcode"});
  // 40 lists, each holding the previous one twice: 2^40 values once unfolded.
  std::string doubling = "]K\x05\x61q\x00\x30"s;
  for (int k = 0; k < 40; ++k) doubling += "](h\x00h\x00\x65q\x00\x30"s;
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy(doubling + "(h\x00l"s, 1), "h"); },
                   {"h: the array unfolds into ",
                    " values or more (lists referred to from "
                    "several places count at each); expected at most 20000000"});
  // A range of 10^9 numbers (refused before any is made); the limit holds for all the ranges of
  // a file together: two of 500,001 numbers.
  ExpectInputError(
      [] {
        DecodeNpyObjects(ObjectNpy("(cbuiltins\nrange\nK\x00J\x00\xca\x9a\x3b\x86Rl"s, 1), "h");
      },
      {"h: REDUCE at byte 142: the range objects make 1000000000 numbers in all; expected at "
       "most 1000000"});
  std::string ranges = "(";
  for (int k = 0; k < 2; ++k) ranges += "c__builtin__\nxrange\nJ\x21\xa1\x07\x00\x85R"s;
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy(ranges + "l", 2), "h"); },
                   {"h: REDUCE at byte",
                    "make 500001 + 500001 numbers in all; expected at "
                    "most 1000000"});
  // 11 object arrays built from one list of a million elements: 11 million elements.
  std::string arrays = "(" + ObjectArrayOps(1000000, "(" + std::string(1000000, 'N') + "lq\x01");
  for (int k = 1; k < 11; ++k) arrays += ObjectArrayOps(1000000, "h\x01");
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy(arrays + "l", 11), "h"); },
                   {"h: BUILD at byte",
                    "the arrays hold 10000000 + 1000000 elements in all; expected at most "
                    "10000000"});
  // Integers beyond 64 bits.
  ExpectInputError(
      [] {
        DecodeNpyObjects(ObjectNpy("(\x8a\x09\x00\x00\x00\x00\x00\x00\x00\x80\x00l"s, 1), "h");
      },
      {"LONG1 at byte", "does not fit 64 bits"});
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(L99999999999999999999L\nl", 1), "h"); },
                   {"LONG at byte", "is not an integer that fits 64 bits"});
  // The header and the pickle disagree; the pickle holds no array.
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(K\x01l"s, 1, "(2,)"), "h"); },
                   {"h: the pickled array has shape (1,), the header says (2,)"});
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(K\x01K\x02l"s, 1), "h"); },
                   {"holds a list of 2 items, not a list of 1"});
  ExpectInputError([] { DecodeNpyObjects(WithObjectHeader("]."), "h"); },
                   {"h: the pickle holds a list, not a NumPy array"});
  ExpectInputError([] { DecodeNpyObjects(WithObjectHeader("a."), "h"); },
                   {"APPEND at byte 0 finds the stack empty"});
  ExpectInputError([] { DecodeNpyObjects(WithObjectHeader("]t."), "h"); },
                   {"TUPLE at byte 1 finds no MARK"});
  ExpectInputError([] { DecodeNpyObjects(WithObjectHeader("h\x07."s), "h"); },
                   {"BINGET at byte 0 reads memo entry 7, unset"});
  // Numeric data NumPy writes but the reader does not convert.
  ExpectInputError(
      [] { DecodeNpyObjects(NpyHeaderOf("'>i4'", "(1,)") + std::string(4, '\0'), "h"); },
      {"h: big-endian data (dtype '>i4') are not read"});
  ExpectInputError(
      [] { DecodeNpyObjects(NpyHeaderOf("'<u8'", "(1,)") + std::string(7, '\0') + "\x80", "h"); },
      {"h: the uint64 value 9223372036854775808 does not fit a signed 64-bit integer"});
  ExpectInputError(
      [] { DecodeNpyObjects(NpyHeaderOf("'<c8'", "(1,)") + std::string(8, '\0'), "h"); },
      {"h: dtype \"<c8\" is not read"});
  ExpectInputError([] { DecodeNpyObjects(NpyHeaderOf("'<i2'", "(3,)") + "\x01\x00"s, "h"); },
                   {"h: truncated data"});
}

// Protocol 0 writes numbers and strings as text: Python 2 string escapes, raw-unicode-escape,
// I01 for True, an L suffix on longs.
TEST(NpyObjects, ProtocolZeroText) {
  const NpyObjects m = DecodeNpyObjects(
      ObjectNpy("(lp0\nS'a\\x41\\n'\naV\\u00e9\naI01\naL123L\naF1.5\naI-7\na", 6), "p");
  ASSERT_EQ(m.items.size(), 6u);
  EXPECT_EQ(m.items[0]->kind, Kind::kBytes);
  EXPECT_EQ(m.items[0]->text, "aA\n");
  EXPECT_EQ(m.items[1]->kind, Kind::kText);
  EXPECT_EQ(m.items[1]->text, "\xc3\xa9");  // U+00E9 in UTF-8
  EXPECT_EQ(m.items[2]->kind, Kind::kBool);
  EXPECT_EQ(m.items[2]->integer, 1);
  EXPECT_EQ(m.items[3]->integer, 123);
  EXPECT_EQ(m.items[4]->real, 1.5);
  EXPECT_EQ(m.items[5]->integer, -7);
  ExpectInputError([] { DecodeNpyObjects(ObjectNpy("(V\\u12\nl", 1), "p"); },
                   {"p: UNICODE at byte", "has an escape that is not read"});
}

// make.py: GThard = eye(4), GTsoft = |i - j| <= 1, both bool, by np.savez and
// np.savez_compressed; zip64.npz holds GThard = eye(3).
TEST(Npz, ReadsStoredDeflatedAndZip64Members) {
  for (const std::string name : {"gt.npz", "gt_compressed.npz"}) {
    SCOPED_TRACE(name);
    const std::string zip = Data(name);
    EXPECT_EQ(NpzMemberNames(zip, Q(name)), (std::vector<std::string>{"GThard.npy", "GTsoft.npy"}));
    const cv::Mat1f hard = DecodeNpyMatrix(NpzMember(zip, "GThard.npy", Q(name)), "GThard");
    const cv::Mat1f soft = DecodeNpyMatrix(NpzMember(zip, "GTsoft", Q(name)), "GTsoft");
    ASSERT_EQ(hard.size(), cv::Size(4, 4));
    ASSERT_EQ(soft.size(), cv::Size(4, 4));
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        EXPECT_EQ(hard(i, j), i == j ? 1.f : 0.f) << i << ", " << j;
        EXPECT_EQ(soft(i, j), std::abs(i - j) <= 1 ? 1.f : 0.f) << i << ", " << j;
      }
    }
    const NpyObjects objects = DecodeNpyObjects(NpzMember(zip, "GThard", Q(name)), "GThard");
    EXPECT_EQ(objects.shape, (Ints64{4, 4}));
    ASSERT_EQ(objects.items.size(), 16u);
    for (int k = 0; k < 16; ++k) {
      EXPECT_EQ(objects.items[k]->kind, Kind::kBool);
      EXPECT_EQ(objects.items[k]->integer, k % 5 == 0 ? 1 : 0);
    }
  }
  const std::string zip = Data("zip64.npz");
  EXPECT_EQ(NpzMemberNames(zip, "z"), std::vector<std::string>{"GThard.npy"});
  const cv::Mat1f eye = DecodeNpyMatrix(NpzMember(zip, "GThard.npy", "z"), "GThard");
  ASSERT_EQ(eye.size(), cv::Size(3, 3));
  EXPECT_EQ(cv::countNonZero(eye != cv::Mat1f::eye(3, 3)), 0);
}

TEST(Npz, MissingMembersDamageAndOtherFilesAreRefused) {
  const std::string zip = Data("gt.npz");
  ExpectInputError([&] { NpzMember(zip, "GTmissing.npy", Q("gt.npz")); },
                   {Q("gt.npz") + ": has no member \"GTmissing.npy\"; its members are " +
                    "\"GThard.npy\", \"GTsoft.npy\""});
  // GTsoft's first data byte changed: its CRC-32 fails; GThard is intact.
  const std::string damaged = Data("gt_damaged_crc.npz");
  ExpectInputError([&] { NpzMember(damaged, "GTsoft.npy", "d"); },
                   {"d: member \"GTsoft.npy\" is damaged: its data have CRC-32 0x"});
  EXPECT_EQ(NpzMember(damaged, "GThard.npy", "d"), NpzMember(zip, "GThard.npy", "d"));
  // Not ZIP archives.
  ExpectInputError([] { NpzMemberNames(Data("gt_lists.npy"), "n"); },
                   {"n: not a ZIP archive (.npz): no end-of-central-directory record (it is a "
                    ".npy file)"});
  ExpectInputError([] { NpzMember("garbage", "GThard.npy", "n"); }, {"n: not a ZIP archive"});
  ExpectInputError([] { NpzMemberNames("", "n"); }, {"n: not a ZIP archive"});
  // The first member's compression method (central directory byte 10) and flags (byte 8).
  const std::size_t directory = zip.find("PK\x01\x02"s);
  ASSERT_NE(directory, std::string::npos);
  std::string bzip2 = zip;
  bzip2[directory + 10] = 12;
  ExpectInputError([&] { NpzMember(bzip2, "GThard.npy", "b"); },
                   {"b: member \"GThard.npy\" is compressed with bzip2, which is not read"});
  std::string encrypted = zip;
  encrypted[directory + 8] = 1;
  ExpectInputError([&] { NpzMember(encrypted, "GThard.npy", "e"); },
                   {"e: member \"GThard.npy\" is encrypted"});
}

// Every prefix and random changes of the archives: an InputError or a result, no crash.
TEST(Npz, TruncatedAndDamagedArchives) {
  for (const std::string name : {"gt.npz", "gt_compressed.npz", "zip64.npz"}) {
    const std::string good = Data(name);
    for (std::size_t n = 0; n < good.size(); ++n) {
      const std::string prefix = good.substr(0, n);
      const std::string message = InputErrorMessage([&] { NpzMemberNames(prefix, "t"); });
      ASSERT_EQ(message.rfind("t: ", 0), 0u) << name << " cut at " << n << ": " << message;
    }
    std::mt19937 random(7);
    std::uniform_int_distribution<std::size_t> where(0, good.size() - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int trial = 0; trial < 3000; ++trial) {
      std::string bytes = good;
      bytes[where(random)] = static_cast<char>(byte(random));
      try {
        for (const std::string& member : NpzMemberNames(bytes, "t")) NpzMember(bytes, member, "t");
      } catch (const InputError&) {
      }
    }
  }
}

// A bool .npy of rows x cols, eye-like (cell (i, i) true).
std::string BoolNpy(int rows, int cols) {
  std::string data =
      NpyHeaderOf("'|b1'", "(" + std::to_string(rows) + ", " + std::to_string(cols) + ")");
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) data += static_cast<char>(i == j ? 1 : 0);
  return data;
}

// The archives of tests/io/zip_writer.h read as Python's zipfile reads them (checked once by
// hand with zipfile.ZipFile(...).testzip() and read()).
TEST(Npz, ReadsArchivesOfTheTestWriter) {
  const std::string eye = BoolNpy(3, 3);
  for (const bool deflate : {false, true}) {
    const std::string zip =
        ZipArchive({{"GThard.npy", eye, deflate}, {"GTsoft.npy", "x", deflate}});
    EXPECT_EQ(NpzMemberNames(zip, "z"), (std::vector<std::string>{"GThard.npy", "GTsoft.npy"}));
    EXPECT_EQ(NpzMember(zip, "GThard", "z"), eye);
    EXPECT_EQ(NpzMember(zip, "GTsoft.npy", "z"), "x");
  }
  // Deflate data of more than one block.
  const std::string large(200000, '\x01');
  EXPECT_EQ(NpzMember(ZipArchive({{"a.npy", large}}), "a.npy", "z"), large);
}

// The size a member declares is compared with what the caller can use before anything is
// allocated or inflated; data that inflate to more than they declare are damaged.
TEST(Npz, MemberLargerThanTheCallerExpectsIsRefusedBeforeInflating) {
  const std::string zip = ZipArchive({{"GThard.npy", BoolNpy(300, 300)}});
  const std::uint64_t size = BoolNpy(300, 300).size();  // 90000 cells and the header
  NpzLimit limit;
  limit.bytes = 66336;
  limit.expected = "a 10x10 matrix";
  ExpectInputError([&] { NpzMember(zip, "GThard.npy", Q("GT.npz"), limit); },
                   {Q("GT.npz") + ": member \"GThard.npy\" holds " + std::to_string(size) +
                    " bytes once inflated (the size the archive declares); expected at most "
                    "66336: a 10x10 matrix"});
  limit.bytes = size;  // exactly the size: read
  EXPECT_EQ(NpzMember(zip, "GThard.npy", "z", limit), BoolNpy(300, 300));
  // A declared size of 2^32 - 2 (a 4 GB allocation) with 12 bytes of data behind it: refused by
  // the default limit (1 GiB) before the ratio of deflate is even looked at.
  ExpectInputError(
      [] {
        NpzMember(ZipArchive({{"GThard.npy", "abc", true, 0xfffffffe}}), "GThard.npy", "z");
      },
      {"z: member \"GThard.npy\" holds 4294967294 bytes once inflated (the size the archive "
       "declares); expected at most 1073741824"});
  // Within the limit, but the data inflate to more than declared: damaged, the buffer is the
  // declared size. Stored members must declare their real size.
  ExpectInputError(
      [] {
        NpzMember(ZipArchive({{"GThard.npy", std::string(5000, 'a'), true, 100}}), "GThard", "z");
      },
      {"z: member \"GThard.npy\": damaged deflate data (they do not inflate to the 100 bytes "
       "announced)"});
  ExpectInputError(
      [] {
        NpzMember(ZipArchive({{"GThard.npy", "abcd", false, 100}}), "GThard", "z");
      },
      {"z: member \"GThard.npy\" is stored with sizes that differ (4 and 100 bytes)"});
}

// Archives that NumPy (Python's zipfile) would read otherwise than this reader are refused.
TEST(Npz, ArchivesThatMeanSomethingElseToNumpyAreRefused) {
  const std::string hard = BoolNpy(2, 2), other = BoolNpy(3, 3);
  // Two members of one name: np.load reads the last, this reader would read the first.
  const std::string twice = ZipArchive({{"GThard.npy", hard}, {"GThard.npy", other}});
  for (const auto& read :
       std::vector<std::function<void()>>{[&] { NpzMemberNames(twice, Q("GT.npz")); },
                                          [&] { NpzMember(twice, "GThard", Q("GT.npz")); }}) {
    ExpectInputError(read, {Q("GT.npz") + ": the archive holds two members named "
                                          "\"GThard.npy\" (entries 1 and 2 of its central "
                                          "directory); expected one member of each name (NumPy "
                                          "reads the last of them, this reader would read the "
                                          "first"});
  }
  // A duplicate of another member than the one asked for is refused as well.
  ExpectInputError(
      [] {
        NpzMember(ZipArchive({{"GTsoft.npy", "a"}, {"GThard.npy", "b"}, {"GTsoft.npy", "c"}}),
                  "GThard", "z");
      },
      {"z: the archive holds two members named \"GTsoft.npy\" (entries 1 and 3"});
  // "GThard" and "GThard.npy": np.load's key "GThard" reads the first, this reader the second.
  ExpectInputError(
      [&] {
        NpzMember(ZipArchive({{"GThard", other}, {"GThard.npy", hard}}), "GThard", "z");
      },
      {"z: the archive holds members named \"GThard\" and \"GThard.npy\", which np.load takes "
       "for one (entries 1 and 2"});
  // An entry the end record does not count: zipfile reads it, and it may be a second GThard.
  ExpectInputError(
      [&] {
        NpzMemberNames(ZipArchive({{"GThard.npy", hard}, {"GThard.npy", other}}, 1), "z");
      },
      {"z: damaged ZIP archive: its central directory holds ",
       " bytes after the 1 members its "
       "end record announces"});
  // A local header that names another file (zipfile refuses it).
  ZipEntry renamed{"GThard.npy", hard};
  renamed.local_name = "GTsoft.npy";
  ExpectInputError([&] { NpzMember(ZipArchive({renamed}), "GThard.npy", "z"); },
                   {"z: member \"GThard.npy\": its local header at byte 0 names another file"});
  // An archive appended to other bytes: zipfile moves every offset by their length.
  ExpectInputError(
      [&] {
        NpzMemberNames(ZipArchive({{"GThard.npy", hard}}, -1, "prefix"), "z");
      },
      {"z: damaged ZIP archive: its central directory ends at byte ", "its end record is at byte ",
       "expected them to meet"});
}

// An archive without members (np.savez of nothing: 22 bytes) says so.
TEST(Npz, EmptyArchiveSaysItIsEmpty) {
  const std::string empty = ZipArchive({});
  ASSERT_EQ(empty.size(), 22u);
  EXPECT_TRUE(IsNpzArchive(empty));
  EXPECT_TRUE(IsNpzArchive(ZipArchive({{"a.npy", "x"}})));
  EXPECT_FALSE(IsNpzArchive(Data("gt_lists.npy")));
  EXPECT_FALSE(IsNpzArchive("PK"));
  EXPECT_TRUE(NpzMemberNames(empty, "e").empty());
  ExpectInputError([&] { NpzMember(empty, "GThard", Q("GT.npz")); },
                   {Q("GT.npz") + ": is an empty ZIP archive (no member); expected one holding "
                                  "\"GThard\""});
}

// What a caller can use bounds the pickle's work: the header's element count before the pickle
// runs, a range before its numbers are made, numeric arrays inside the pickle, and the values
// the array unfolds into with memoised lists counted at each place.
TEST(NpyObjects, CallersLimitsAreAppliedBeforeTheWorkIsDone) {
  NpyObjectLimits limits;
  limits.values = 100;
  limits.expected = "the run's 3 queries";
  // The header announces 200 elements.
  ExpectInputError(
      [&] { DecodeNpyObjects(ObjectNpy("(K\x01l"s, 1, "(100, 2)"), "h", limits); },
      {"h: shape (100, 2) holds 200 elements; expected at most 100 (the run's 3 queries)"});
  ExpectInputError(
      [&] {
        DecodeNpyObjects(NpyHeaderOf("'<i8'", "(101,)") + std::string(808, '\0'), "h", limits);
      },
      {"h: shape (101,) holds 101 elements; expected at most 100"});
  // A range of 10^9 numbers: refused with the caller's limit, before any number is made.
  ExpectInputError(
      [&] {
        DecodeNpyObjects(ObjectNpy("(cbuiltins\nrange\nK\x00J\x00\xca\x9a\x3b\x86Rl"s, 1), "h",
                         limits);
      },
      {"h: REDUCE at byte ",
       ": the range objects make 1000000000 numbers in all; expected at "
       "most 100 (the run's 3 queries)"});
  // A range longer than one list may be, however few the numbers in all.
  NpyObjectLimits one_list;
  one_list.range = 59;
  one_list.expected = "a query's references";
  ExpectInputError(
      [&] { DecodeNpyObjects(ObjectNpy("(cbuiltins\nrange\nK\x3c\x85Rl"s, 1), "h", one_list); },
      {"h: REDUCE at byte ",
       ": range(0, 60, 1) makes 60 numbers; expected at most 59 in one "
       "list (a query's references)"});
  one_list.range = 60;
  EXPECT_EQ(DecodeNpyObjects(ObjectNpy("(cbuiltins\nrange\nK\x3c\x85Rl"s, 1), "h", one_list)
                .items[0]
                ->items.size(),
            60u);
  // A range of 60 numbers held by 2 elements: 1 + 2 x 61 = 123 values once unfolded.
  const std::string memoised = "(cbuiltins\nrange\nK\x3c\x85Rq\x01h\x01l"s;
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy(memoised, 2), "h", limits); },
                   {"h: the array unfolds into ",
                    " values or more (lists referred to from "
                    "several places count at each); expected at most 100 (the run's 3 queries)"});
  limits.values = 123;
  const NpyObjects read = DecodeNpyObjects(ObjectNpy(memoised, 2), "h", limits);
  ASSERT_EQ(read.items.size(), 2u);
  EXPECT_EQ(read.items[0], read.items[1]);  // one list, referred to twice
  EXPECT_EQ(read.items[1]->items.size(), 60u);
  // A numeric array inside the pickle (protocol 5's _frombuffer) counts its elements.
  limits.values = 10;
  const std::string buffer = "(cnumpy.core.numeric\n_frombuffer\n(B\x58\x00\x00\x00"s +
                             std::string(88, '\0') +
                             "cnumpy\ndtype\nX\x02\x00\x00\x00i8\x85RK\x0b\x85X\x01\x00\x00\x00"
                             "CtRl"s;
  // Without a limit it is read: eleven zeros.
  ASSERT_EQ(Ints(*DecodeNpyObjects(ObjectNpy(buffer, 1), "h").items[0]), Ints64(11, 0));
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy(buffer, 1), "h", limits); },
                   {"h: REDUCE at byte ",
                    ": the arrays hold 11 elements in all; expected at "
                    "most 10"});
}

// The matrix fuzzer's seeds (tests/fuzz/corpus/matrix; the first byte chooses the extension
// of the fuzzer's file, the rest is the file) read as the fuzzer reads them, with the default
// limits: a result or one line naming the source. The seeds of archives NumPy reads otherwise,
// of an archive without members, of a size beyond the default and of a range memoised by every
// row are refused, each by its own check.
TEST(NpyObjects, MatrixFuzzerSeedsAreReadOrRefusedInOneLine) {
  const std::string corpus = testing::SourceDir() + "/tests/fuzz/corpus/matrix";
  const auto one_line = [](const std::function<void()>& read) {
    try {
      read();
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find_first_of("\r\n"), std::string::npos) << message;
      EXPECT_EQ(message.rfind("fuzz", 0), 0u) << message;
      return message;
    }
    return std::string();
  };
  // Each seed's refusals: as a .npy file, then as an archive (listing its members, reading each,
  // or, with none listed, the member GThard).
  std::map<std::string, std::string> refusals;
  for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
    const std::string name = entry.path().filename().string();
    const std::string bytes = ReadBytes(entry.path().string()).substr(1);
    std::string& message = refusals[name];
    message = one_line([&] { DecodeNpyObjects(bytes, "fuzz.npy"); }) + " | ";
    std::vector<std::string> members;
    message += one_line([&] { members = NpzMemberNames(bytes, "fuzz.npz"); });
    for (const std::string& member : members)
      message += one_line([&] { NpzMember(bytes, member, "fuzz.npz"); });
    if (members.empty()) message += one_line([&] { NpzMember(bytes, "GThard", "fuzz.npz"); });
  }
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"npz_duplicate_member.npz", "two members named \"GThard.npy\""},
      {"npz_numpy_alike_names.npz", "members named \"GThard\" and \"GThard.npy\""},
      {"npz_uncounted_entry.npz", "bytes after the 1 members its end record announces"},
      {"npz_after_other_bytes.npz", "expected them to meet"},
      {"npz_local_name_differs.npz", "its local header at byte 0 names another file"},
      {"npz_declared_4gb.npz", "holds 4294967294 bytes once inflated"},
      {"npz_empty.npz", "is an empty ZIP archive (no member)"},
      {"objects_memoised_range.npy",
       "the range objects make 2000000 numbers in all; expected "
       "at most 1000000"},
  };
  for (const auto& [seed, part] : expected) {
    ASSERT_EQ(refusals.count(seed), 1u) << seed << " is not in " << corpus;
    EXPECT_NE(refusals[seed].find(part), std::string::npos) << seed << ": " << refusals[seed];
  }
  // The archives NumPy writes are read whole.
  for (const char* seed : {"objects_gt.npz", "objects_gt_compressed.npz", "objects_zip64.npz"}) {
    const std::string& message = refusals[seed];
    EXPECT_EQ(message.substr(message.find(" | ")), " | ") << seed;
  }
}

TEST(NpyMatrix, RefusesObjectArraysWithAHint) {
  ExpectInputError([] { DecodeNpyMatrix(Data("gt_lists.npy"), Q("gt_lists.npy")); },
                   {Q("gt_lists.npy") +
                    ": holds Python objects (dtype object, pickled); expected a numeric matrix"});
}

}  // namespace
}  // namespace openable
