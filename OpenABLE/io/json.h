// The JSON documents the toolbox writes (run reports, evaluations, sweeps, the auto mode, the
// SNAPS figures), built on nlohmann-json (Debian's nlohmann-json3-dev). Documents are
// nlohmann::ordered_json, so members are written in the order they were added; numbers that
// come from computations go through json::Number, and a document becomes text through
// json::Dump (docs/output_formats.md, "Reports as JSON").
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace openable {

using Json = nlohmann::ordered_json;

namespace json {

// `value` rounded to `significant` digits exactly as printf's %.<significant>g rounds it, or null
// when it is NaN or infinite (JSON has neither). The figures of the reports use 9 digits, the
// SNAPS figures 6. The %g text is read back: as an integer when it has no point and no
// exponent ("1685", not 1685.0), else as the double nearest to it, which Dump writes with the
// same digits.
Json Number(double value, int significant = 9);

// A JSON array of strings.
Json Strings(const std::vector<std::string>& items);

// The text of `document` as the files hold it: two spaces of indentation per level, one member
// or element per line, ": " after names, "{}" and "[]" when empty, and a final newline.
// Written here rather than by nlohmann's dump() for one reason, its numbers: nlohmann writes a
// double with Grisu2, which is not always the shortest text that reads back (0.01530851 can
// come out as 0.015308510000000001), while every double here is written as printf's %.9g
// writes it (NaN and infinities as null): the texts the toolbox has always written, and at
// most 9 significant digits whatever was stored. Strings (and names) are shown by the rule of
// every text output first (ToValidUtf8, base/strings.h: a path in another encoding has each
// byte outside a well-formed UTF-8 sequence written \xNN, so the JSON string holds \\xNN),
// then escaped by nlohmann (quotes, backslashes, control characters). nlohmann's own
// error_handler_t could only refuse the document, drop such bytes or write U+FFFD for them,
// which would make names that differ in those bytes read the same.
std::string Dump(const Json& document);

// `document` on one line exactly as nlohmann's dump() writes it (the data embedded in the HTML
// report), its strings and names shown by the same rule as Dump's. For a document whose text
// is all valid UTF-8 the same bytes as dump().
std::string DumpLine(const Json& document);

}  // namespace json
}  // namespace openable
