#include "OpenABLE/base/strings.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "OpenABLE/base/error.h"
#include "tests/test_support.h"

namespace openable {
namespace {

TEST(Strings, SplitTrimmedKeepsEmptyPieces) {
  EXPECT_EQ(SplitTrimmed(" a , b,c ", ','), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(SplitTrimmed("a,,b", ','), (std::vector<std::string>{"a", "", "b"}));
  EXPECT_EQ(SplitTrimmed("", ','), (std::vector<std::string>{""}));
  EXPECT_EQ(SplitTrimmed("x | y |", '|'), (std::vector<std::string>{"x", "y", ""}));
  EXPECT_EQ(SplitTrimmed("1,1;2,1", ';'), (std::vector<std::string>{"1,1", "2,1"}));
}

TEST(Strings, TrimAndFormat) {
  EXPECT_EQ(Trim(" \tx y\r\n"), "x y");
  EXPECT_EQ(FormatFixed(0.12345, 3), "0.123");
  EXPECT_EQ(FormatNumber(2500), "2500");
}

// The texts printf's %g writes, as the reports and files have always held them.
TEST(Strings, FormatNumberWritesPrintfG) {
  EXPECT_EQ(FormatNumber(0.47), "0.47");
  EXPECT_EQ(FormatNumber(1e6), "1e+06");
  EXPECT_EQ(FormatNumber(1234567.0), "1.23457e+06");
  EXPECT_EQ(FormatNumber(1.0 / 3.0, 9), "0.333333333");
  EXPECT_EQ(FormatNumber(0.1 + 0.2, 9), "0.3");
  EXPECT_EQ(FormatNumber(0.1 + 0.2, 17), "0.30000000000000004");
  EXPECT_EQ(FormatNumber(1e-5, 9), "1e-05");
  EXPECT_EQ(FormatNumber(-2.5, 9), "-2.5");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(FormatNumber(-std::numeric_limits<double>::infinity(), 9), "-inf");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(FormatFixed(2.0 / 3.0, 9), "0.666666667");
  EXPECT_EQ(FormatFixed(-0.04, 1), "-0.0");
}

// The well-formed UTF-8 byte sequences, The Unicode Standard, Table 3-7:
//   U+0000..U+007F      00..7F
//   U+0080..U+07FF      C2..DF  80..BF
//   U+0800..U+0FFF      E0      A0..BF  80..BF
//   U+1000..U+CFFF      E1..EC  80..BF  80..BF
//   U+D000..U+D7FF      ED      80..9F  80..BF
//   U+E000..U+FFFF      EE..EF  80..BF  80..BF
//   U+10000..U+3FFFF    F0      90..BF  80..BF  80..BF
//   U+40000..U+FFFFF    F1..F3  80..BF  80..BF  80..BF
//   U+100000..U+10FFFF  F4      80..8F  80..BF  80..BF
// Each is kept as it is; every byte outside them is written \xNN. Expected texts by hand.
TEST(Strings, ToValidUtf8KeepsEveryWellFormedSequence) {
  // The first and last sequence of each row of the table.
  const char* const kEnds[] = {"\x7f",
                               "\xc2\x80",
                               "\xdf\xbf",
                               "\xe0\xa0\x80",
                               "\xe0\xbf\xbf",
                               "\xe1\x80\x80",
                               "\xec\xbf\xbf",
                               "\xed\x80\x80",
                               "\xed\x9f\xbf",
                               "\xee\x80\x80",
                               "\xef\xbf\xbf",
                               "\xf0\x90\x80\x80",
                               "\xf0\xbf\xbf\xbf",
                               "\xf1\x80\x80\x80",
                               "\xf3\xbf\xbf\xbf",
                               "\xf4\x80\x80\x80",
                               "\xf4\x8f\xbf\xbf"};
  for (const char* s : kEnds) EXPECT_EQ(ToValidUtf8(s), s) << s;
  EXPECT_EQ(ToValidUtf8(std::string("\0", 1)), std::string("\0", 1));
  EXPECT_EQ(ToValidUtf8(""), "");
  // Names as users write them come out byte for byte: accents, symbols, emoji, and the
  // backslashes, quotes and control characters that other layers escape.
  for (const char* s : {"caf\xc3\xa9 0001.png", "\xe2\x82\xac 5 \xf0\x9f\x98\x80.jpg",
                        "\xe6\x9d\xb1\xe4\xba\xac/frame.png", "back\\slash \\xe9 \"q\"\n\t.png"})
    EXPECT_EQ(ToValidUtf8(s), s) << s;
}

TEST(Strings, ToValidUtf8EscapesEveryByteOutsideAWellFormedSequence) {
  // A byte of another encoding (Latin-1 e acute) and lone continuation bytes.
  EXPECT_EQ(ToValidUtf8("caf\xe9.png"), "caf\\xe9.png");
  EXPECT_EQ(ToValidUtf8("\x80"), "\\x80");
  EXPECT_EQ(ToValidUtf8(std::string("a\xbf") + "b"), "a\\xbfb");
  EXPECT_EQ(ToValidUtf8("\xc3\xa9\xa9"), "\xc3\xa9\\xa9");  // a continuation byte too many
  // Overlong forms: C0 and C1 never start a sequence; E0 needs A0..BF after it, F0 90..BF.
  EXPECT_EQ(ToValidUtf8("\xc0\xaf"), "\\xc0\\xaf");  // '/' in two bytes
  EXPECT_EQ(ToValidUtf8("\xc0\x80"), "\\xc0\\x80");
  EXPECT_EQ(ToValidUtf8("\xc1\xbf"), "\\xc1\\xbf");
  EXPECT_EQ(ToValidUtf8("\xe0\x80\xaf"), "\\xe0\\x80\\xaf");
  EXPECT_EQ(ToValidUtf8("\xe0\x9f\xbf"), "\\xe0\\x9f\\xbf");  // U+07FF in three bytes
  EXPECT_EQ(ToValidUtf8("\xf0\x80\x80\xaf"), "\\xf0\\x80\\x80\\xaf");
  EXPECT_EQ(ToValidUtf8("\xf0\x8f\xbf\xbf"), "\\xf0\\x8f\\xbf\\xbf");  // U+FFFF in four
  // Surrogates D800..DFFF (ED A0..BF ..), alone or paired as CESU-8 writes U+1F600.
  EXPECT_EQ(ToValidUtf8("\xed\xa0\x80"), "\\xed\\xa0\\x80");
  EXPECT_EQ(ToValidUtf8("\xed\xbf\xbf"), "\\xed\\xbf\\xbf");
  EXPECT_EQ(ToValidUtf8("\xed\xa0\xbd\xed\xb8\x80"), "\\xed\\xa0\\xbd\\xed\\xb8\\x80");
  // Beyond U+10FFFF: F4 90.., F5..F7, and the old 5- and 6-byte forms; FE and FF.
  EXPECT_EQ(ToValidUtf8("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");
  EXPECT_EQ(ToValidUtf8("\xf5\x80\x80\x80"), "\\xf5\\x80\\x80\\x80");
  EXPECT_EQ(ToValidUtf8("\xf7\xbf\xbf\xbf"), "\\xf7\\xbf\\xbf\\xbf");
  EXPECT_EQ(ToValidUtf8("\xf8\x88\x80\x80\x80"), "\\xf8\\x88\\x80\\x80\\x80");
  EXPECT_EQ(ToValidUtf8("\xfc\x84\x80\x80\x80\x80"), "\\xfc\\x84\\x80\\x80\\x80\\x80");
  EXPECT_EQ(ToValidUtf8("\xfe\xff"), "\\xfe\\xff");
  // Truncated sequences: at the end, before ASCII, before a well-formed sequence (which is
  // kept), and a lead byte cut off by another lead.
  EXPECT_EQ(ToValidUtf8("\xc3"), "\\xc3");
  EXPECT_EQ(ToValidUtf8("cut\xe2\x82"), "cut\\xe2\\x82");
  EXPECT_EQ(ToValidUtf8("\xf0\x9f\x98"), "\\xf0\\x9f\\x98");
  EXPECT_EQ(ToValidUtf8("\xe2\x82.png"), "\\xe2\\x82.png");
  EXPECT_EQ(ToValidUtf8("\xe2\x82\xe2\x82\xac"), "\\xe2\\x82\xe2\x82\xac");
  EXPECT_EQ(ToValidUtf8("\xf0\x9f\xc3\xa9"), "\\xf0\\x9f\xc3\xa9");
  EXPECT_EQ(ToValidUtf8("\xe2\xf0\x9f\x98\x80"), "\\xe2\xf0\x9f\x98\x80");
  EXPECT_EQ(ToValidUtf8("\xc3\xa9\xe9\xc3\xa9"), "\xc3\xa9\\xe9\xc3\xa9");
}

// Names that differ only in their invalid bytes stay distinct, and the result is valid UTF-8
// that the conversion leaves as it is.
TEST(Strings, ToValidUtf8KeepsNamesApartAndIsValid) {
  EXPECT_NE(ToValidUtf8("caf\xe9.png"), ToValidUtf8("caf\xe8.png"));
  EXPECT_NE(ToValidUtf8("\xe2\x82"), ToValidUtf8("\xe2"));
  for (const char* s : {"caf\xe9.png", "\xed\xa0\x80/\xc0\xaf", "\xf4\x90\x80\x80\xe2\x82",
                        "\xff\xfe\xfd", "ok \xc3\xa9 \xc3"}) {
    const std::string shown = ToValidUtf8(s);
    EXPECT_EQ(testing::FirstInvalidUtf8Byte(shown), std::string::npos) << shown;
    EXPECT_EQ(ToValidUtf8(shown), shown);
  }
}

// UTF-8 written out by its definition (bit patterns), for every code point in the shortest
// form, and in longer (overlong) forms.
std::string Encode(std::uint32_t c, int length) {
  if (length == 1) return std::string(1, static_cast<char>(c));
  const unsigned char lead[] = {0, 0, 0xc0, 0xe0, 0xf0};
  std::string out(static_cast<std::size_t>(length), '\0');
  for (int k = length - 1; k > 0; --k, c >>= 6) out[k] = static_cast<char>(0x80 | (c & 0x3f));
  out[0] = static_cast<char>(lead[length] | c);
  return out;
}

std::string Escaped(const std::string& bytes) {
  static const char* const kHex = "0123456789abcdef";
  std::string out;
  for (const char ch : bytes) {
    const auto u = static_cast<unsigned char>(ch);
    out += std::string("\\x") + kHex[u >> 4] + kHex[u & 0xf];
  }
  return out;
}

// Every scalar value in its shortest form is kept; a surrogate, a code point beyond U+10FFFF
// (up to the largest a 4-byte form holds) and every overlong form are escaped whole.
TEST(Strings, ToValidUtf8OverEveryCodePoint) {
  int wrong = 0;
  for (std::uint32_t c = 0; c < 0x200000 && wrong < 10; ++c) {
    const int length = c < 0x80 ? 1 : c < 0x800 ? 2 : c < 0x10000 ? 3 : 4;
    const std::string bytes = Encode(c, length);
    const bool scalar = c <= 0x10ffff && !(c >= 0xd800 && c <= 0xdfff);
    const std::string expected = scalar ? bytes : Escaped(bytes);
    if (ToValidUtf8(bytes) != expected) {
      ++wrong;
      ADD_FAILURE() << "U+" << std::hex << c;
    }
    for (int longer = std::max(length + 1, 2); longer <= 4; ++longer) {
      if (ToValidUtf8(Encode(c, longer)) != Escaped(Encode(c, longer))) {
        ++wrong;
        ADD_FAILURE() << "U+" << std::hex << c << " in " << longer << " bytes";
      }
    }
  }
}

// Quoted (error messages) shows names by the same rule, inside its own escapes.
TEST(Strings, QuotedShowsInvalidBytesAsEscapes) {
  EXPECT_EQ(Quoted("dir/caf\xe9\n\"x\".png"), "\"dir/caf\\xe9\\n\\\"x\\\".png\"");
  EXPECT_EQ(Quoted("caf\xc3\xa9.png"), "\"caf\xc3\xa9.png\"");
  EXPECT_EQ(Quoted("\xed\xa0\x80\x01"), "\"\\xed\\xa0\\x80\\x01\"");
}

}  // namespace
}  // namespace openable

namespace openable {
namespace {

struct FakeSize {
  int width, height;
};

TEST(SizeText, IsWidthTimesHeight) {
  EXPECT_EQ(SizeText(640, 480), "640x480");
  EXPECT_EQ(SizeText(FakeSize{1241, 376}), "1241x376");
  EXPECT_EQ(SizeText(0, 0), "0x0");
}

}  // namespace
}  // namespace openable
