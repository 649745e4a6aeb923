// Internal helpers of the evaluation readers (matrix_file.cc, ground_truth.cc, pairs_file.cc):
// whole-file reading with one-line errors, and number parsing without locale surprises.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace openable::evaluation_internal {

// Throws InputError "<where> does not exist ..." / "<where> is a folder, not a regular file" /
// ... unless `path` is a regular file that can be read (base/input_file.h).
void RequireFile(const std::string& path, const std::string& where);

// The whole content of `path` (base/input_file.h); throws InputError starting with `where`.
std::string ReadWholeFile(const std::string& path, const std::string& where);

// Blank characters that separate fields (not '\n').
inline bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// A whole token as a number ("1", "-2.5e3", "+4", "nan", "inf"); false on anything else.
bool ParseNumber(std::string_view token, double* value);

// A whole field as an integer of at most kMaxIndex in size; "12.0" is accepted as 12. (The
// bound leaves room for the arithmetic of frame numbers: a base or a first frame subtracted.)
inline constexpr std::int64_t kMaxIndex = 1000000000000000;  // 10^15
bool ParseIndex(std::string_view field, std::int64_t* value);

// One line of a text file: its number (from 1), its fields (split at blanks and commas, the
// comment left out; "1,,2" gives an empty field, a trailing comma none) and its comment (the
// text after '#').
struct Line {
  int number = 0;
  std::vector<std::string_view> fields;
  std::string_view comment;
};

// The header rule of the text readers (pairs, positions): the first line with fields is a
// header when none of its fields begins like a number (a digit, or a sign or point and a
// digit): "a,b" and "x y z" are headers, "12;34" is data (and refused as such, naming the
// value), so that a line of numbers in an unexpected separator is never dropped in silence.
bool IsHeaderLine(const Line& line);

// The fields of `s` as Line::fields describes them.
void SplitFields(std::string_view s, std::vector<std::string_view>* out);

// Calls f(const Line&) for every line of `data` (a UTF-8 byte order mark is skipped).
template <typename F>
void ForEachLine(const std::string& data, F&& f) {
  Line line;
  std::size_t pos = data.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  while (pos < data.size()) {
    std::size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    const std::string_view text(data.data() + pos, end - pos);
    pos = end + 1;
    ++line.number;
    const std::size_t hash = text.find('#');
    line.comment = hash == std::string_view::npos ? std::string_view() : text.substr(hash + 1);
    SplitFields(text.substr(0, hash), &line.fields);
    f(static_cast<const Line&>(line));
  }
}

}  // namespace openable::evaluation_internal
