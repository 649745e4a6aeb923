// Pickled NumPy object arrays and .npz archives: the files of tests/data/npy_objects (written by
// its make.py, whose values are stated here), hand-written pickles, and damaged or hostile bytes.
#include "OpenABLE/io/npy_objects.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "OpenABLE/base/error.h"
#include "OpenABLE/io/npy.h"
#include "tests/test_support.h"

namespace openable {
namespace {

using namespace std::string_literals;
using testing::ExpectInputError;
using testing::InputErrorMessage;
using testing::Q;
using testing::ReadBytes;
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
                   {"unfolds into more than 100000000 values"});
  // A range of 10^9 numbers (refused before any is made); the limit holds for all the ranges of
  // a file together: two of 1,000,001 numbers.
  ExpectInputError(
      [] {
        DecodeNpyObjects(ObjectNpy("(cbuiltins\nrange\nK\x00J\x00\xca\x9a\x3b\x86Rl"s, 1), "h");
      },
      {"the range objects make more than 2000000 numbers in all"});
  std::string ranges = "(";
  for (int k = 0; k < 2; ++k) ranges += "c__builtin__\nxrange\nJ\x41\x42\x0f\x00\x85R"s;
  ExpectInputError([&] { DecodeNpyObjects(ObjectNpy(ranges + "l", 2), "h"); },
                   {"h: REDUCE at byte", "more than 2000000 numbers in all"});
  // 11 object arrays built from one list of a million elements: 11 million elements.
  std::string arrays = "(" + ObjectArrayOps(1000000, "(" + std::string(1000000, 'N') + "lq\x01");
  for (int k = 1; k < 11; ++k) arrays += ObjectArrayOps(1000000, "h\x01");
  ExpectInputError(
      [&] { DecodeNpyObjects(ObjectNpy(arrays + "l", 11), "h"); },
      {"h: BUILD at byte", "the object arrays hold more than 10000000 elements in all"});
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

TEST(NpyMatrix, RefusesObjectArraysWithAHint) {
  ExpectInputError([] { DecodeNpyMatrix(Data("gt_lists.npy"), Q("gt_lists.npy")); },
                   {Q("gt_lists.npy") +
                    ": holds Python objects (dtype object, pickled); expected a numeric matrix"});
}

}  // namespace
}  // namespace openable
