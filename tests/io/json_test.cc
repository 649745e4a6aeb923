// The JSON layer of every document the toolbox writes (io/json.h), against texts written out
// by hand.
#include "OpenABLE/io/json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace openable {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One value as a document holds it.
std::string Text(const Json& value) {
  const std::string text = json::Dump(value);
  return text.substr(0, text.size() - 1);  // without the final newline
}

TEST(Json, NotFiniteNumbersAreNull) {
  EXPECT_EQ(Text(json::Number(std::nan(""))), "null");
  EXPECT_EQ(Text(json::Number(-std::nan(""))), "null");
  EXPECT_EQ(Text(json::Number(kInf)), "null");
  EXPECT_EQ(Text(json::Number(-kInf)), "null");
  EXPECT_EQ(Text(json::Number(kInf, 6)), "null");
}

TEST(Json, NumbersAreRoundedToNineSignificantDigitsAsPrintfDoes) {
  EXPECT_EQ(Text(json::Number(0.1 + 0.2)), "0.3");
  EXPECT_EQ(Text(json::Number(1.0 / 3.0)), "0.333333333");
  EXPECT_EQ(Text(json::Number(2.0 / 3.0)), "0.666666667");
  EXPECT_EQ(Text(json::Number(-2.0 / 3.0)), "-0.666666667");
  EXPECT_EQ(Text(json::Number(58.4299130449)), "58.429913");
  EXPECT_EQ(Text(json::Number(1.05096852349)), "1.05096852");
  EXPECT_EQ(Text(json::Number(1e-5)), "1e-05");
  EXPECT_EQ(Text(json::Number(0.000123456789123)), "0.000123456789");
  EXPECT_EQ(Text(json::Number(0.01530851)), "0.01530851");  // Grisu2 writes 0.015308510000000001
  EXPECT_EQ(Text(json::Number(-0.0)), "-0");
  // Whole numbers stay whole, as %g writes them.
  EXPECT_EQ(Text(json::Number(1685.0)), "1685");
  EXPECT_EQ(Text(json::Number(-1.0)), "-1");
  EXPECT_EQ(Text(json::Number(0.0)), "0");
  EXPECT_EQ(Text(json::Number(123456789.4)), "123456789");
  // Beyond nine digits, an exponent as %g writes it.
  EXPECT_EQ(Text(json::Number(1234567890123.0)), "1.23456789e+12");
  EXPECT_EQ(Text(json::Number(1e9)), "1e+09");
  // Six digits for the SNAPS figures.
  EXPECT_EQ(Text(json::Number(24124.1234, 6)), "24124.1");
  EXPECT_EQ(Text(json::Number(6.24281234e-06, 6)), "6.24281e-06");
}

TEST(Json, StringsAreEscaped) {
  EXPECT_EQ(Text("say \"hi\""), R"("say \"hi\"")");
  EXPECT_EQ(Text("back\\slash"), R"("back\\slash")");
  EXPECT_EQ(Text("two\nlines\ttab\r"), R"("two\nlines\ttab\r")");
  EXPECT_EQ(Text(std::string("nul\x01\x1f", 5)), R"("nul\u0001\u001f")");
  EXPECT_EQ(Text("caf\xc3\xa9 /path"), "\"caf\xc3\xa9 /path\"");  // UTF-8 kept as is
  Json keyed;
  keyed["a\"b"] = 1;
  EXPECT_EQ(json::Dump(keyed), "{\n  \"a\\\"b\": 1\n}\n");  // names too
}

// Text that is not valid UTF-8 (a path in another encoding) is neither refused nor replaced by
// U+FFFD: each byte outside a well-formed sequence is written \xNN (ToValidUtf8), as in every
// other output, so the JSON text holds \\xNN. Names too, and DumpLine writes the same strings.
TEST(Json, InvalidUtf8IsShownAsEscapesNotRefused) {
  Json doc;
  doc["path"] = std::string("bad\xff\xfe name\xc3");
  doc["caf\xe9"] = Json::array({"\xed\xa0\x80", "ok \xc3\xa9"});
  EXPECT_EQ(json::Dump(doc),
            "{\n  \"path\": \"bad\\\\xff\\\\xfe name\\\\xc3\",\n  \"caf\\\\xe9\": [\n"
            "    \"\\\\xed\\\\xa0\\\\x80\",\n    \"ok \xc3\xa9\"\n  ]\n}\n");
  EXPECT_EQ(json::DumpLine(doc),
            "{\"path\":\"bad\\\\xff\\\\xfe name\\\\xc3\",\"caf\\\\xe9\":"
            "[\"\\\\xed\\\\xa0\\\\x80\",\"ok \xc3\xa9\"]}");
  // Read back, the strings are the escapes.
  EXPECT_EQ(Json::parse(json::Dump(doc))["path"], "bad\\xff\\xfe name\\xc3");
}

// DumpLine is nlohmann's one-line dump() for text that is valid UTF-8.
TEST(Json, DumpLineIsNlohmannsDumpForValidText) {
  Json doc;
  doc["a"] = {1, 2.5, "caf\xc3\xa9 \"q\"\n", nullptr, true};
  doc["b"] = Json::object();
  EXPECT_EQ(json::DumpLine(doc), doc.dump());
}

TEST(Json, DumpIndentsByTwoSpacesKeepsOrderAndEndsWithANewline) {
  Json doc;
  doc["program"] = "Test_OpenABLE";
  doc["b"] = 1;
  doc["a"] = json::Number(0.5);
  doc["nothing"] = json::Number(std::nan(""));
  doc["raw"] = 0.1 + 0.2;  // a double stored as it is: written with 9 digits all the same
  doc["nan"] = std::nan("");
  doc["list"] = json::Strings({"x", "y"});
  doc["empty"] = json::Strings({});
  doc["object"] = {{"z", true}, {"y", Json()}, {"n", {{"deep", Json::array({1, -2})}}}};
  EXPECT_EQ(json::Dump(doc),
            "{\n"
            "  \"program\": \"Test_OpenABLE\",\n"
            "  \"b\": 1,\n"
            "  \"a\": 0.5,\n"
            "  \"nothing\": null,\n"
            "  \"raw\": 0.3,\n"
            "  \"nan\": null,\n"
            "  \"list\": [\n"
            "    \"x\",\n"
            "    \"y\"\n"
            "  ],\n"
            "  \"empty\": [],\n"
            "  \"object\": {\n"
            "    \"z\": true,\n"
            "    \"y\": null,\n"
            "    \"n\": {\n"
            "      \"deep\": [\n"
            "        1,\n"
            "        -2\n"
            "      ]\n"
            "    }\n"
            "  }\n"
            "}\n");
}

TEST(Json, DumpedTextReadsBackToTheSameValues) {
  Json doc;
  doc["third"] = json::Number(1.0 / 3.0);
  doc["count"] = 300;
  doc["label"] = "LDB L=10";
  const Json back = Json::parse(json::Dump(doc));
  EXPECT_EQ(back, doc);
  EXPECT_DOUBLE_EQ(back["third"].get<double>(), 0.333333333);
}

}  // namespace
}  // namespace openable
