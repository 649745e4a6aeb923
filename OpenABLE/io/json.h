// The JSON documents the toolbox writes (run reports, evaluations, sweeps, the auto mode, the
// SNAPS figures), built on nlohmann-json (Debian's nlohmann-json3-dev). Documents are
// nlohmann::ordered_json, so members are written in the order they were added; numbers that
// come from computations go through json::Number, and a document becomes text through
// json::Dump (docs/output_formats.md, "JSON").
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace openable {

using Json = nlohmann::ordered_json;

namespace json {

// `value` rounded to `significant` digits exactly as printf's %.<significant>g rounds it, or null
// when it is NaN or infinite (JSON has neither). The figures of the reports use 9 digits, the
// SNAPS figures 6. The rounding is done here, on the value, rather than in a serializer of our
// own: the %g text is read back (as an integer when it has no point and no exponent, so "1685"
// stays "1685" and not "1685.0"), and nlohmann's shortest round-trip printing of the read-back
// double gives back the same digits. Only the spelling of large or tiny numbers may differ from
// %g's ("1e+09" is written 1000000000.0; exponents start at 1e-05 and 1e+15): the same value.
Json Number(double value, int significant = 9);

// A JSON array of strings.
Json Strings(const std::vector<std::string>& items);

// The text of `document` as the files hold it: two spaces of indentation per level, one member
// or element per line, ": " after names, and a final newline. Strings are escaped by nlohmann
// (quotes, backslashes, control characters); text that is not valid UTF-8 (a path in another
// encoding) has each invalid byte replaced by U+FFFD (error_handler_t::replace) instead of
// making the whole document fail.
std::string Dump(const Json& document);

}  // namespace json
}  // namespace openable
