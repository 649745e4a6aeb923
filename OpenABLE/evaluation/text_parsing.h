// Internal helpers of the evaluation readers (matrix_file.cc, ground_truth.cc): whole-file
// reading with one-line errors, and number parsing without locale surprises.
#pragma once

#include <string>
#include <string_view>

namespace openable::evaluation_internal {

// Throws InputError "<where>: file not found" / "is a folder; expected a file" unless `path`
// is an existing file that is not a folder.
void RequireFile(const std::string& path, const std::string& where);

// The whole content of `path` (after RequireFile); throws InputError starting with `where`.
std::string ReadWholeFile(const std::string& path, const std::string& where);

// Blank characters that separate fields (not '\n').
inline bool IsBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// A whole token as a number ("1", "-2.5e3", "+4", "nan", "inf"); false on anything else.
bool ParseNumber(std::string_view token, double* value);

}  // namespace openable::evaluation_internal
